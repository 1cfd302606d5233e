"""The pipeline's polarisation output (``render.polarization``): variables, the sky frame
checked from the dataset's own geometry by an independent route (right ascension and
declination unit vectors), band integration, refusals, and the overview's DoLP panel."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
import yaml

from speclight.errors import InputError
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate


def _scenario(tmp_path, **render: object) -> dict:
    data = yaml.safe_load(example_text("calsphere"))
    data["time"] = {"start": "2020-02-29T21:16:00Z", "stop": "2020-02-29T21:16:20Z", "step_s": 5}
    data["spectrum"] = {"min_nm": 400, "max_nm": 900, "step_nm": 5}
    data["instrument"]["bands"] = data["instrument"]["bands"][:4]  # B, G, R, V
    data["target"]["materials"]["body"] = {
        "bsdf": "ggx",
        "roughness": 0.3,
        "reflectance": {"conductor": "Al"},
    }
    data["render"].update({"resolution_px": 24, "polarization": True, **render})
    return data


@pytest.fixture(scope="module")
def ds(tmp_path_factory: pytest.TempPathFactory) -> xr.Dataset:
    folder = tmp_path_factory.mktemp("pol")
    loaded = parse_scenario(yaml.safe_dump(_scenario(folder)), base_dir=folder)
    return simulate(loaded).dataset


def _rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate v (N, 3) by unit quaternions q (N, 4) (w, x, y, z): v + 2w(u x v) + 2u x (u x v)."""
    w, u = q[:, :1], q[:, 1:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def test_variables_and_frame(ds: xr.Dataset) -> None:
    for name in ("intensity_q", "intensity_u", "intensity_v"):
        assert ds[name].dims == ("time", "wavelength") and ds[name].attrs["units"] == "W sr-1 nm-1"
    for name in ("count_rate_q", "count_rate_u", "count_rate_v", "dolp", "aolp"):
        assert ds[name].dims == ("time", "band")
    assert "north" in ds.attrs["polarization_frame"]
    assert "GCRS" in ds["aolp"].attrs["comment"]
    lit = np.isfinite(ds["dolp"].values).all(axis=1)
    assert lit.sum() >= 3
    assert np.all((ds["dolp"].values[lit] > 0.001) & (ds["dolp"].values[lit] < 1.0))


def _scattering_normal_position_angle(ds: xr.Dataset) -> np.ndarray:
    """Position angle [deg, mod 180] of the scattering plane's normal, via RA/Dec vectors."""
    q = ds["attitude_quaternion"].values
    s = _rotate(q, ds["sun_direction_body"].values)
    o = _rotate(q, ds["observer_direction_body"].values)
    d = -o  # line of sight to the target (GCRS)
    ra, dec = np.arctan2(d[:, 1], d[:, 0]), np.arcsin(d[:, 2])
    e_ra = np.stack([-np.sin(ra), np.cos(ra), np.zeros_like(ra)], axis=1)
    e_dec = np.stack([-np.sin(dec) * np.cos(ra), -np.sin(dec) * np.sin(ra), np.cos(dec)], axis=1)
    normal = np.cross(s, o)
    return np.degrees(np.arctan2((normal * e_ra).sum(1), (normal * e_dec).sum(1))) % 180.0


def _assert_aolp_is_the_scattering_normal(ds: xr.Dataset) -> None:
    pa = _scattering_normal_position_angle(ds)
    lit = np.isfinite(ds["aolp"].values).all(axis=1)
    assert lit.sum() >= 2
    for b in range(ds.sizes["band"]):
        diff = (ds["aolp"].values[lit, b] - pa[lit] + 90.0) % 180.0 - 90.0
        assert np.all(np.abs(diff) < 1e-6)


def test_aolp_is_the_scattering_plane_normal_on_the_sky(ds: xr.Dataset) -> None:
    # s-polarisation (conductors: R_s > R_p) lies along the normal to the scattering plane;
    # its position angle from the dataset's geometry, through RA/Dec unit vectors
    _assert_aolp_is_the_scattering_normal(ds)


def test_articulated_plastic_target_is_s_polarised_too(tmp_path) -> None:
    # Sun-tracking arrays (articulated, rendered per pose) of coated plastic: the coat's
    # reflection is s-polarised, the bases unpolarised, so the AoLP is the same angle
    data = yaml.safe_load(example_text("gnss-meo"))
    data["time"] = {"start": "2024-10-15T21:00:00Z", "stop": "2024-10-15T21:03:00Z", "step_s": 60}
    data["render"].update({"resolution_px": 24, "polarization": True})
    out = simulate(parse_scenario(yaml.safe_dump(data), base_dir=tmp_path)).dataset
    assert np.nanmax(out["dolp"].values) > 1e-3
    _assert_aolp_is_the_scattering_normal(out)


def test_band_dolp_is_a_weighted_mean_of_the_spectral_dolp(ds: xr.Dataset) -> None:
    # Q/I per wavelength has one sign and angle; a band's Q/I is a positive-weighted mean
    i = ds["intensity"].values
    p = np.hypot(ds["intensity_q"].values, ds["intensity_u"].values) / np.where(i > 0, i, np.nan)
    lit = np.isfinite(ds["dolp"].values).all(axis=1)
    lo, hi = np.nanmin(p[lit], axis=1), np.nanmax(p[lit], axis=1)
    band = ds["dolp"].values[lit]
    assert np.all((band >= lo[:, None] - 1e-12) & (band <= hi[:, None] + 1e-12))
    assert np.all(ds["count_rate_v"].values[lit] == 0.0)


def test_map_mode_refuses_polarization(tmp_path) -> None:
    data = _scenario(tmp_path, mode="map", map_file="m.zarr")
    with pytest.raises(InputError, match="polarization"):
        parse_scenario(yaml.safe_dump(data), base_dir=tmp_path)


def test_polarization_off_writes_no_polarization(tmp_path) -> None:
    data = _scenario(tmp_path, polarization=False)
    out = simulate(parse_scenario(yaml.safe_dump(data), base_dir=tmp_path)).dataset
    assert "dolp" not in out and "intensity_q" not in out and "polarization_frame" not in out.attrs


def test_overview_has_a_dolp_panel(ds: xr.Dataset) -> None:
    from speclight.plot.overview import overview_figure

    fig = overview_figure(ds)
    titles = [ax.get_title(loc="left") for ax in fig.axes]
    assert any(t.startswith("linear polarisation per band") for t in titles)
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_earthshine_adds_its_stokes(tmp_path) -> None:
    data = _scenario(tmp_path)
    data["illumination"] = {"sun": True, "earthshine": {"albedo": 0.3, "samples": 16}}
    out = simulate(parse_scenario(yaml.safe_dump(data), base_dir=tmp_path)).dataset
    lit = np.isfinite(out["dolp"].values).all(axis=1)
    assert lit.sum() >= 3 and np.all(out["dolp"].values[lit] > 0)
    assert np.all(np.isfinite(out["intensity_q"].values[lit]))


def test_stokes_standard_errors(tmp_path, ds: xr.Dataset) -> None:
    # single mode is exact: zero error. Path mode on a convex microfacet sphere: every sample
    # is one reflection at the same half vector (distant Sun and observer), so each sample's
    # Q/I and U/I is the same Fresnel ratio and the relative standard errors of Q and U must
    # be those of I (to the mixing of wavelengths within a bin: 10 %)
    lit = ds["intensity"].values > 0
    for c in "quv":
        assert ds[f"intensity_{c}_std"].attrs["units"] == "W sr-1 nm-1"
        assert np.all(ds[f"intensity_{c}_std"].values[lit] == 0)
    data = _scenario(tmp_path, mode="path", samples_per_pixel=4)
    out = simulate(parse_scenario(yaml.safe_dump(data), base_dir=tmp_path)).dataset
    assert np.array_equal(out["intensity"].values > 0, lit) and lit.sum() > 100
    from speclight.info import run_variants

    assert out.attrs["render_variant"] == run_variants()[2]  # what `speclight info` reports
    i, i_std = out["intensity"].values[lit], out["intensity_std"].values[lit]
    for c in "qu":
        x, x_std = out[f"intensity_{c}"].values[lit], out[f"intensity_{c}_std"].values[lit]
        ratio = (x_std / np.abs(x)) / (i_std / i)
        assert np.all((ratio > 0.9) & (ratio < 1.1))
