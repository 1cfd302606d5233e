"""Can a scenario be the measured target? (estimate/inputs/geometry_match.py)

Reference: skyfield's topocentric direction of the calsphere example's element set (its own
SGP4 and frames, not speclight's): where skyfield sees the satellite, a measurement recorded
there is accepted; 30 deg away, or a day later when skyfield has it below the horizon, it is
refused; a file made for another catalogue number is refused.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from skyfield.api import EarthSatellite, wgs84

from speclight.errors import InputError
from speclight.estimate.inputs.geometry_match import catalogue_number, check_scenario_sees
from speclight.orbit.timescale import load_timescale, time_from_utc
from speclight.scenario import example_text, parse_scenario

L1 = "1 01520U 65065H   20058.86916325  .00000035  00000-0  49354-4 0  9992"
L2 = "2 01520  90.0403 128.7439 0072289 113.7399 336.8322 13.35807489655439"
PASS = np.datetime64("2020-02-29T21:16:00", "ns") + np.arange(0, 240, 20).astype("timedelta64[s]")


def _skyfield_altaz(times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    sat = EarthSatellite(L1, L2, "CALSPHERE 4A", load_timescale())
    site = wgs84.latlon(48.7822, 9.1967, elevation_m=355.0)
    alt, az, _ = (sat - site).at(time_from_utc(times)).altaz()
    return az.degrees, alt.degrees


def _recorded(path: Path, times: np.ndarray, az: np.ndarray, el: np.ndarray, yaml: str) -> Path:
    ds = xr.Dataset(
        {"azimuth": ("time", az), "elevation": ("time", el)},
        coords={"time": times},
        attrs={"scenario_yaml": yaml},
    )
    ds.to_netcdf(path, engine="h5netcdf")
    return path


def test_catalogue_numbers() -> None:
    assert catalogue_number(parse_scenario(example_text("calsphere"), source="c")) == 1520


def test_where_skyfield_sees_it_passes_and_elsewhere_not(tmp_path: Path) -> None:
    loaded = parse_scenario(example_text("calsphere"), source="calsphere.yaml")
    az, el = _skyfield_altaz(PASS)
    assert np.all(el > 0)
    own = _recorded(tmp_path / "own.nc", PASS, az, el, example_text("calsphere"))
    check_scenario_sees(loaded, own, PASS, "laser")
    turned = _recorded(tmp_path / "turned.nc", PASS, (az + 30) % 360, el, "")
    with pytest.raises(InputError, match=r"deg from where .* saw the target"):
        check_scenario_sees(loaded, turned, PASS, "laser")
    other = _recorded(tmp_path / "other.nc", PASS, az, el, example_text("box-wing"))
    with pytest.raises(InputError, match=r"catalogue number 1520, but .* was made for"):
        check_scenario_sees(loaded, other, PASS, "laser")


def test_a_day_later_below_the_horizon_is_refused(tmp_path: Path) -> None:
    loaded = parse_scenario(example_text("calsphere"), source="calsphere.yaml")
    later = PASS + np.timedelta64(1, "D")
    assert np.all(_skyfield_altaz(later)[1] < 0)
    csv = tmp_path / "later.csv"  # a CSV records no direction: the horizon check only
    with pytest.raises(InputError, match=r"below the horizon.*no measured epoch lies in it"):
        check_scenario_sees(loaded, csv, later, "sun")
