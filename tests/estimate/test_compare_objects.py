"""speclight compare with an ``object`` column: each object's trajectory from its own rows
(against each satellite's own TLE run), statistics per object against numpy and
scipy.stats.pearsonr, and hostile object names."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from skyfield.api import EarthSatellite, wgs84

from speclight.estimate.comparison.compare_run import compare
from speclight.estimate.inputs.observations import read_observations
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
#: Rows alternate between the two satellites every 10 s (each satellite every 20 s).
EPOCHS = [f"2020-02-29T21:16:{s:02d}" for s in range(0, 60, 10)]
#: As tests/estimate/test_compare.py's nadir test: at a row, the velocity is the average
#: of the two chords around it (error O(h^2)), at an end one chord, off the tangent by half
#: the angle swept in 20 s (n ~ 1e-3 rad/s: 0.01 rad), which turns the cube by as much and
#: changes its faces' projected areas by < 1 %: 0.01 mag.
NADIR_TOL_MAG = 0.01


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


def _rows(tmp_path: Path, with_object: bool = True) -> Path:
    """Rows of satellites A and B interleaved 10 s apart, each placed where skyfield's SGP4
    puts it (azimuth, elevation, range from Stuttgart at 0 m); magnitudes are arbitrary
    (8.0 + 0.1 k)."""
    ts = load_timescale()
    sats = [EarthSatellite(*tle, name, ts) for tle, name in ((TLE_A, "A"), (TLE_B, "B"))]
    lat, lon, _ = STUTTGART_0M
    header = "time,magnitude,magnitude_sigma,band,latitude_deg,longitude_deg,"
    header += "elevation_deg,azimuth_deg,range_m" + (",object" if with_object else "")
    rows = [header]
    for k, epoch in enumerate(EPOCHS):
        sat = sats[k % 2]
        t = ts.utc(*[int(x) for x in epoch.replace("T", "-").replace(":", "-").split("-")])
        el, az, dist = (sat - wgs84.latlon(lat, lon, elevation_m=0.0)).at(t).altaz()
        row = f"{epoch}Z,{8.0 + 0.1 * k},0.05,G-600/40,{lat},{lon},"
        row += f"{float(el.degrees)!r},{float(az.degrees)!r},{float(dist.m)!r}"
        rows.append(row + (f",{'AB'[k % 2]}-{k % 2}" if with_object else ""))
    path = tmp_path / ("objects.csv" if with_object else "plain.csv")
    path.write_text("\n".join(rows) + "\n")
    return path


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> dict:
    tmp = tmp_path_factory.mktemp("objects")
    obs = read_observations(_rows(tmp))
    placed = compare(parse_scenario(yaml.safe_dump(_scenario(None))), obs)
    own = {  # each satellite's rows against its own TLE
        j: compare(parse_scenario(yaml.safe_dump(_scenario(tle))), obs).dataset
        for j, tle in enumerate((TLE_A, TLE_B))
    }
    return {"obs": obs, "placed": placed, "own": own}


def test_each_object_is_placed_on_its_own_trajectory(runs) -> None:
    ds = runs["placed"].dataset
    sim = ds["magnitude_simulated"].values
    assert np.isfinite(sim).all()
    for j in (0, 1):
        rows = np.arange(len(EPOCHS)) % 2 == j
        np.testing.assert_allclose(
            sim[rows], runs["own"][j]["magnitude_simulated"].values[rows], atol=NADIR_TOL_MAG
        )
    assert ds["object"].values.tolist() == ["A-0", "B-1"]
    assert ds["object_id"].values.tolist() == ["A-0", "B-1"] * 3
