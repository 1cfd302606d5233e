"""A geometry-only scenario (no target) needs no attitude: left out, the body frame is the
GCRS; a scenario that renders (a target, or a reflectivity map) still needs one."""

from __future__ import annotations

from datetime import UTC

import numpy as np
import pytest
import yaml
from skyfield.api import EarthSatellite, load, wgs84

from speclight.errors import InputError
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate

#: Angle between speclight's and skyfield's target-to-observer directions [rad]: both run
#: SGP4 on the same elements; their TEME -> GCRS rotations and Earth orientation agree to
#: metres, i.e. ~1e-5 rad at the ~1,000 km ranges of the pass. 1e-4 rad leaves a factor 10.
DIRECTION_TOLERANCE_RAD = 1e-4


def _geometry_only(**changes: object) -> dict:
    d = yaml.safe_load(example_text("box-wing"))
    d.pop("target")
    d.pop("attitude")
    d["time"]["step_s"] = 120.0
    d["observer"]["light_time"] = False  # skyfield's vectors below are geometric
    d.update(changes)
    return d


def test_geometry_only_runs_without_attitude_in_the_gcrs_frame() -> None:
    d = _geometry_only()
    ds = simulate(parse_scenario(yaml.safe_dump(d), source="geo.yaml")).dataset
    n = ds.sizes["time"]
    np.testing.assert_array_equal(ds["attitude_quaternion"].values, [[1.0, 0, 0, 0]] * n)
    assert not (ds["flags"].values & 64).any()  # no attitude_undefined
    # reference: skyfield's SGP4 and WGS84 site, target -> observer in the GCRS
    ts = load.timescale(builtin=True)
    name, line1, line2 = d["orbit"]["tle"].strip().split("\n")
    sat = EarthSatellite(line1, line2, name, ts)
    site = wgs84.latlon(
        d["observer"]["latitude_deg"], d["observer"]["longitude_deg"], d["observer"]["altitude_m"]
    )
    t = ts.from_datetimes(
        [x.astype("datetime64[us]").item().replace(tzinfo=UTC) for x in ds.time.values]
    )
    to_site = (site.at(t).position.m - sat.at(t).position.m).T
    to_site /= np.linalg.norm(to_site, axis=1, keepdims=True)
    got = ds["observer_direction_body"].values
    angle = np.arccos(np.clip(np.sum(got * to_site, axis=1), -1.0, 1.0))
    assert angle.max() < DIRECTION_TOLERANCE_RAD


def test_a_target_needs_an_attitude() -> None:
    d = yaml.safe_load(example_text("box-wing"))
    d.pop("attitude")
    with pytest.raises(InputError, match=r"\n  attitude: missing, and the target needs one"):
        parse_scenario(yaml.safe_dump(d), source="s.yaml")


def test_a_map_render_needs_an_attitude() -> None:
    d = _geometry_only(render={"mode": "map", "map_file": "m.zarr"})
    with pytest.raises(InputError, match=r"attitude: missing, and the render.mode: map needs"):
        parse_scenario(yaml.safe_dump(d), source="s.yaml")
