"""speclight compare with an ``object`` column: each object's trajectory from its own rows
(against each satellite's own TLE run), statistics per object against numpy and
scipy.stats.pearsonr, an object seen once, and hostile object names."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import scipy.stats
import yaml
from skyfield.api import EarthSatellite, wgs84

from speclight import schema
from speclight.errors import InputError
from speclight.estimate.comparison.compare_run import compare
from speclight.estimate.inputs.observations import MAX_OBJECT_CHARS, read_observations
from speclight.orbit.timescale import load_timescale
from speclight.orbit.tle import checksum
from speclight.scenario import example_text, parse_scenario

#: Calsphere 4A (the calsphere example's element set) and a second satellite in a plane 1.5 deg
#: of right ascension of the ascending node east (~110 km across the track at 48 deg N).
TLE_A = (
    "1 01520U 65065H   20058.86916325  .00000035  00000-0  49354-4 0  9992",
    "2 01520  90.0403 128.7439 0072289 113.7399 336.8322 13.35807489655439",
)
_B2 = TLE_A[1][:17] + f"{128.7439 + 1.5:8.4f}" + TLE_A[1][25:68]
TLE_B = (TLE_A[0], _B2 + str(checksum(_B2)))
STUTTGART_0M = (48.7822, 9.1967, 0.0)
#: Rows alternate between the two satellites every 10 s (each satellite every 20 s):
#: (epoch, satellite, object name).
INTERLEAVED = [
    (f"2020-02-29T21:16:{s:02d}", k % 2, f"{'AB'[k % 2]}-{k % 2}")
    for k, s in enumerate(range(0, 60, 10))
]
#: One more object, seen once (at satellite A's position): no velocity there.
LONELY = ("2020-02-29T21:16:05", 0, "C-2")
#: As tests/estimate/test_compare.py's nadir test: at a row, the velocity is the average
#: of the two chords around it (error O(h^2)), at an end one chord, off the tangent by half
#: the angle swept in 20 s (n ~ 1e-3 rad/s: 0.01 rad), which turns the cube by as much and
#: changes its faces' projected areas by < 1 %: 0.01 mag.
NADIR_TOL_MAG = 0.01
#: The same as a rotation of the body about nadir [rad]: a chord of 20 s turns from the
#: tangent by at most half the angle swept, (n_max 20 s) / 2, n_max = n (1 + e)^2 /
#: (1 - e^2)^(3/2) at perigee (mean motion n = 13.358 rev/day = 9.71e-4 rad/s, e = 0.0072):
#: 9.99e-3 rad; a unit vector turned by that moves by at most as much.
CHORD_ANGLE_RAD = 9.71e-4 * (1 + 0.0072) ** 2 / (1 - 0.0072**2) ** 1.5 * 20.0 / 2
#: float64 sums of a few magnitudes ~8 agree to ~1e-15 relative; far below any rounding
#: that matters in a statistic.
STAT_RTOL = 1e-12


def _scenario(tle: tuple[str, str] | None) -> dict:
    """The calsphere example made a nadir-pointing Lambertian bus with a solar array (its
    look depends on the velocity's direction: the array spans the body's y-z plane), no
    atmosphere, 64 px."""
    data = yaml.safe_load(example_text("calsphere"))
    data["atmosphere"] = {"model": "none"}
    data["render"]["resolution_px"] = 64
    data["instrument"] = {
        "bands": [{"name": "G-600/40", "gaussian": {"center_nm": 600, "sigma_nm": 40}}]
    }
    data["observer"].update(min_elevation_deg=0.0, altitude_m=0.0)
    data["target"] = {
        "shape": {"builtin": "bus_array"},
        "materials": {"*": {"bsdf": "lambertian", "reflectance": 0.5}},
    }
    data["attitude"] = {"model": "nadir"}
    data["orbit"] = {"tle": "\n".join(tle)} if tle else {"observed": True}
    return data


def _rows(tmp_path: Path, rows: list[tuple[str, int, str]], with_object: bool = True) -> Path:
    """Observations of ``rows`` (epoch, satellite 0 = A or 1 = B, object name), each placed
    where skyfield's SGP4 puts that satellite (azimuth, elevation, range from Stuttgart at
    0 m); magnitudes are arbitrary (8.0 + 0.1 k)."""
    ts = load_timescale()
    sats = [EarthSatellite(*tle, name, ts) for tle, name in ((TLE_A, "A"), (TLE_B, "B"))]
    lat, lon, _ = STUTTGART_0M
    header = "time,magnitude,magnitude_sigma,band,latitude_deg,longitude_deg,"
    lines = [header + "elevation_deg,azimuth_deg,range_m" + (",object" if with_object else "")]
    for k, (epoch, j, name) in enumerate(rows):
        t = ts.utc(*[int(x) for x in epoch.replace("T", "-").replace(":", "-").split("-")])
        el, az, dist = (sats[j] - wgs84.latlon(lat, lon, elevation_m=0.0)).at(t).altaz()
        row = f"{epoch}Z,{8.0 + 0.1 * k},0.05,G-600/40,{lat},{lon},"
        row += f"{float(el.degrees)!r},{float(az.degrees)!r},{float(dist.m)!r}"
        lines.append(row + (f",{name}" if with_object else ""))
    path = tmp_path / f"obs_{len(rows)}_{int(with_object)}.csv"
    path.write_text("\n".join(lines) + "\n")
    return path


def _compare(tle: tuple[str, str] | None, path: Path):
    return compare(parse_scenario(yaml.safe_dump(_scenario(tle))), read_observations(path))


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> dict:
    tmp = tmp_path_factory.mktemp("objects")
    path = _rows(tmp, [*INTERLEAVED, LONELY])
    return {
        "placed": _compare(None, path),
        # the interleaved rows as one target: one trajectory zigzagging between the two
        "merged": _compare(None, _rows(tmp, INTERLEAVED, with_object=False)).dataset,
        # each satellite's rows against its own TLE
        "own": {j: _compare(tle, path).dataset for j, tle in enumerate((TLE_A, TLE_B))},
    }


def test_each_object_is_placed_on_its_own_trajectory(runs) -> None:
    ds = runs["placed"].dataset
    sim = ds["magnitude_simulated"].values
    n = len(INTERLEAVED)
    assert np.isfinite(sim[:n]).all()
    for j in (0, 1):
        rows = np.array([sat == j for _, sat, _ in INTERLEAVED])
        own = runs["own"][j]
        np.testing.assert_allclose(
            sim[:n][rows], own["magnitude_simulated"].values[:n][rows], atol=NADIR_TOL_MAG
        )
        # the nadir attitude's yaw follows the velocity: the body-frame directions show
        # which trajectory each row was on
        for name in ("observer_direction_body", "sun_direction_body"):
            ref = own[name].values[:n][rows]
            apart = np.linalg.norm(ds[name].values[:n][rows] - ref, axis=1)
            assert apart.max() < CHORD_ANGLE_RAD
            # the reference failure: one trajectory zigzagging through both satellites
            merged = np.linalg.norm(runs["merged"][name].values[rows] - ref, axis=1)
            assert merged.min() > CHORD_ANGLE_RAD
    assert ds["object"].values.tolist() == ["A-0", "B-1", "C-2"]
    assert ds["object_id"].values.tolist() == ["A-0", "B-1"] * 3 + ["C-2"]


def test_an_object_seen_once_has_no_velocity(runs) -> None:
    ds = runs["placed"].dataset
    assert np.isnan(ds["magnitude_simulated"].values[-1])
    assert ds["flags"].values[-1] & schema.FLAG_ATTITUDE_UNDEFINED
    assert int(ds["n_per_object"].values[2]) == 0
    assert any("seen at one epoch only ('C-2')" in note for note in runs["placed"].notes)


def test_an_error_when_every_object_is_seen_once(tmp_path) -> None:
    with pytest.raises(InputError, match="seen at one epoch only"):
        _compare(None, _rows(tmp_path, [LONELY, ("2020-02-29T21:16:15", 1, "D")]))


def test_statistics_overall_and_per_object(runs) -> None:
    ds = runs["placed"].dataset
    obs, sim = ds["magnitude_observed"].values, ds["magnitude_simulated"].values
    ok = np.isfinite(sim)
    # Pearson (1896): scipy.stats.pearsonr; chi-square as SPEC 5.1 defines it, summed here
    # term by term
    r_ref = scipy.stats.pearsonr(obs[ok], sim[ok]).statistic
    np.testing.assert_allclose(ds.attrs["pearson_r"], r_ref, rtol=STAT_RTOL)
    chi_ref = sum((m - o) ** 2 / o for o, m in zip(obs[ok], sim[ok], strict=True)) / ok.sum()
    np.testing.assert_allclose(ds.attrs["chi_square"], chi_ref, rtol=STAT_RTOL)
    for j, name in enumerate(ds["object"].values[:2]):
        rows = (ds["object_id"].values == name) & ok
        res = obs[rows] - sim[rows]
        assert int(ds["n_per_object"].values[j]) == rows.sum() == 3
        np.testing.assert_allclose(
            ds["residual_mean_per_object"].values[j], res.mean(), rtol=STAT_RTOL
        )
        rms = np.sqrt(np.mean(res**2))
        np.testing.assert_allclose(ds["residual_rms_per_object"].values[j], rms, rtol=STAT_RTOL)
        r = scipy.stats.pearsonr(obs[rows], sim[rows]).statistic
        np.testing.assert_allclose(ds["pearson_r_per_object"].values[j], r, rtol=STAT_RTOL)
        chi = sum((m - o) ** 2 / o for o, m in zip(obs[rows], sim[rows], strict=True)) / 3
        np.testing.assert_allclose(ds["chi_square_per_object"].values[j], chi, rtol=STAT_RTOL)
    assert np.isnan(ds["pearson_r_per_object"].values[2])  # no residual
    assert ds["object_id"].attrs["long_name"].startswith("object")


@pytest.mark.parametrize(
    ("cell", "problem"),
    [
        ("", "a value is required"),
        ("   ", "a value is required"),
        ("x" * (MAX_OBJECT_CHARS + 1), f"{MAX_OBJECT_CHARS + 1} characters"),
        ("sat\x07", "unprintable"),
    ],
)
def test_bad_object_names_are_refused(tmp_path, cell: str, problem: str) -> None:
    path = tmp_path / "bad.csv"
    path.write_text(
        "time,magnitude,magnitude_sigma,band,latitude_deg,longitude_deg,object\n"
        "2020-02-29T21:16:00Z,8.0,0.05,G-600/40,48.78,9.20,A\n"
        f"2020-02-29T21:16:10Z,8.0,0.05,G-600/40,48.78,9.20,{cell}\n"
    )
    with pytest.raises(InputError, match=f"line 3, column 'object'.*{problem}"):
        read_observations(path)
