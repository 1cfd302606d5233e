"""Reflection maps of simulated passes against closed forms and the target's geometry.

* A Lambertian sphere of albedo rho and radius r has, seen from any body direction, the
  reflectance factor ``F(a) = (2 / (3 pi)) rho r^2 [sin a + (pi - a) cos a]`` at phase angle
  a (Russell 1916; Hapke 2012, eq. 6.6; tests/simulate/test_simulate_reflectance_factor.py).
  Under coaxial lasers (a = 0) every pixel of its map must therefore hold ``(2/3) rho r^2``,
  however the sphere spins; under the Sun each pixel holds the mean of F over the phase
  angles of its epochs, binned here with astropy-healpix directly.
* A box-wing spinning about an axis across the line of sight, under coaxial lasers: its
  solar wings (7.2 m2 of glossy cover glass, normals +-x) and the bus's +-x faces are seen
  face-on when the observer direction passes +-x, so the brightest pixel must lie near +-x.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from astropy_healpix import healpix_to_xyz, xyz_to_healpix

from speclight.estimate.reflection_maps.reflection_map_run import reflection_map_measured
from speclight.io.netcdf import dataset_bytes
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate

#: Pixel quadrature of a 256 px sphere (tests/simulate/test_simulate_reflectance_factor.py).
SPHERE_RTOL = 5e-3
RHO, RADIUS_M = 0.9, 0.18
NSIDE = 16


def _calsphere(lasers: bool, period_s: float) -> dict:
    d = yaml.safe_load(example_text("calsphere"))
    d["time"] = {"start": "2020-02-29T21:16:00Z", "stop": "2020-02-29T21:19:00Z", "step_s": 3.0}
    d["instrument"].pop("noise", None)
    # a spin spreads the directions over the body sphere (the sphere looks the same)
    d["attitude"] = {
        "model": "spin",
        "spin_axis_ra_deg": 40.0,
        "spin_axis_dec_deg": 20.0,
        "period_s": period_s,
    }
    if lasers:
        site = {k: d["observer"][k] for k in ("latitude_deg", "longitude_deg", "altitude_m")}
        d["illumination"] = {
            "sun": False,
            "lasers": [
                {
                    "name": f"l{w}",
                    **site,
                    "wavelength_nm": w,
                    "linewidth_nm": 0.5,
                    "power_w": 10.0,
                    "repetition_rate_hz": 1000.0,
                    "divergence_arcsec": 10.0,
                }
                for w in (450.0, 635.0, 1064.0)
            ],
        }
    return d


def _write(d: dict, path: Path):
    loaded = parse_scenario(yaml.safe_dump(d), source="test")
    ds = simulate(loaded).dataset
    path.write_bytes(dataset_bytes(ds))
    return loaded, ds


def _law(phase_deg: np.ndarray) -> np.ndarray:
    a = np.radians(phase_deg)
    return 2 / (3 * np.pi) * RHO * RADIUS_M**2 * (np.sin(a) + (np.pi - a) * np.cos(a))


def test_laser_map_of_a_lambert_sphere_is_uniform_at_the_zero_phase_value(tmp_path: Path):
    _, ds = _write(_calsphere(lasers=True, period_s=37.0), tmp_path / "s.nc")
    m = reflection_map_measured(tmp_path / "s.nc", nside=NSIDE)
    assert m.attrs["light"] == "laser" and m.attrs["healpix_order"] == "ring"
    mapped = m["n_samples"].values > 0
    assert mapped.sum() >= 30  # the spin spreads the epochs over many pixels
    f = m["reflectance_factor"].values[:, mapped]
    np.testing.assert_allclose(f, 2 / 3 * RHO * RADIUS_M**2, rtol=SPHERE_RTOL)
    # each epoch sits in the pixel of its observer direction (coaxial: the phase vector)
    d = ds["observer_direction_body"].values
    seen = ds["flags"].values == 0
    expected = xyz_to_healpix(d[seen, 0], d[seen, 1], d[seen, 2], NSIDE, order="ring")
    np.testing.assert_array_equal(m["track_pixel"].values[seen], expected)
    assert np.all(m["track_pixel"].values[~seen] == -1)


@pytest.fixture(scope="module")
def sun_pass(tmp_path_factory: pytest.TempPathFactory):
    folder = tmp_path_factory.mktemp("sun")
    loaded, ds = _write(_calsphere(lasers=False, period_s=23.0), folder / "s.nc")
    return folder, loaded, ds


def _expected_sun_map(ds) -> tuple[np.ndarray, np.ndarray]:
    """Mean of the phase law over the epochs of each pixel, binned with astropy-healpix."""
    lit = (ds["flags"].values == 0) & (ds["sunlit"].values == 1.0)
    v = ds["phase_vector_body"].values[lit]
    pix = xyz_to_healpix(v[:, 0], v[:, 1], v[:, 2], NSIDE, order="ring")
    law = _law(ds["phase_angle"].values[lit])
    n = np.bincount(pix, minlength=12 * NSIDE**2)
    total = np.bincount(pix, weights=law, minlength=12 * NSIDE**2)
    return n, total / np.maximum(n, 1)


def test_sun_map_of_a_lambert_sphere_is_the_phase_law(sun_pass) -> None:
    folder, _, ds = sun_pass
    m = reflection_map_measured(folder / "s.nc", nside=NSIDE)
    assert m.attrs["light"] == "sun"
    n, law = _expected_sun_map(ds)
    np.testing.assert_array_equal(m["n_samples"].values, n)
    mapped = n > 0
    assert mapped.sum() >= 20
    f = m["reflectance_factor"].values
    np.testing.assert_allclose(
        f[:, mapped], np.broadcast_to(law[mapped], f[:, mapped].shape), rtol=SPHERE_RTOL
    )
    assert np.all(np.isnan(f[:, ~mapped]))
    assert "range_offset" not in m  # no lasers, no ranging


def test_csv_with_scenario_gives_the_same_map(sun_pass) -> None:
    folder, loaded, ds = sun_pass
    rate = ds["count_rate"].transpose("time", "band").values
    bands = [str(b) for b in ds["band"].values]
    times = np.datetime_as_string(ds["time"].values, unit="ms")
    lines = ["time," + ",".join(bands)]
    lines += [
        f"{t}Z," + ",".join(f"{x:.17g}" for x in row) for t, row in zip(times, rate, strict=True)
    ]
    csv = folder / "rates.csv"
    csv.write_text("\n".join(lines) + "\n")
    m = reflection_map_measured(csv, nside=NSIDE, loaded=loaded)
    n, law = _expected_sun_map(ds)
    mapped = n > 0
    np.testing.assert_array_equal(m["n_samples"].values, n)
    np.testing.assert_allclose(
        m["reflectance_factor"].values[:, mapped],
        np.broadcast_to(law[mapped], (len(bands), mapped.sum())),
        rtol=SPHERE_RTOL,
    )
    assert "scenario" in m.attrs["direction"]


def test_active_box_wing_map_is_brightest_where_the_wings_face_the_observer(tmp_path: Path):
    d = yaml.safe_load(example_text("box-wing-laser"))
    d["instrument"].pop("noise", None)
    d["render"]["resolution_px"] = 64
    d["illumination"]["sun"] = False
    d["illumination"]["lasers"] = d["illumination"]["lasers"][:7]  # the coaxial ones
    mid = "2019-08-30T02:24:00Z"
    # the line of sight at mid-window, in GCRS (fixed identity attitude: body = GCRS)
    probe = dict(d, time={"start": mid, "stop": mid, "step_s": 1.0})
    probe["attitude"] = {"model": "fixed", "quaternion": [1.0, 0.0, 0.0, 0.0]}
    probe.pop("target")
    probe["illumination"] = {"sun": True}
    u = simulate(parse_scenario(yaml.safe_dump(probe), source="t")).dataset
    los = u["observer_direction_body"].values[0]
    axis = np.cross(los, [0.0, 0.0, 1.0])
    axis /= np.linalg.norm(axis)  # across the line of sight: the track runs near the equator
    period_s, step_s = 10.0, 0.1
    d["attitude"] = {
        "model": "spin",
        "spin_axis_ra_deg": float(np.degrees(np.arctan2(axis[1], axis[0]))),
        "spin_axis_dec_deg": float(np.degrees(np.arcsin(axis[2]))),
        "period_s": period_s,
    }
    d["time"] = {"start": "2019-08-30T02:23:50Z", "stop": "2019-08-30T02:24:10Z", "step_s": step_s}
    _write(d, tmp_path / "bw.nc")
    m = reflection_map_measured(tmp_path / "bw.nc", nside=NSIDE)
    assert m.attrs["light"] == "laser"
    track = m["track_direction_body"].values
    drift_deg = np.degrees(np.max(np.abs(np.arcsin(track[:, 2]))))
    assert drift_deg < 10.0  # the line of sight turns little in 20 s
    f = m["reflectance_factor"].values[2]  # G-638/26: lines at 635 nm
    best = int(np.nanargmax(f))
    x, _, _ = healpix_to_xyz(best, NSIDE, order="ring")
    off_deg = np.degrees(np.arccos(abs(float(x))))  # angle to the nearer of +x, -x
    # the nearest sample to +-x is off by at most the track's drift and half a step of the
    # spin, and a pixel centre is within ~one pixel (3.7 deg at nside 16) of its samples
    half_step_deg = 360.0 * step_s / period_s / 2
    pixel_deg = np.degrees(np.sqrt(4 * np.pi / (12 * NSIDE**2)))
    assert off_deg <= drift_deg + half_step_deg + pixel_deg
    # and the map is far brighter there than edge-on to the wings (+-y)
    edge = np.abs(m["lat"].values) < 10
    edge &= np.abs(np.abs(m["lon"].values) % 180 - 90) < 15
    assert np.nanmax(f[edge]) < 0.3 * f[best]
    assert np.isfinite(m["range_offset"].values[2, best])
