"""Shared pieces of the attitude-profile tests: a real pass and skyfield's view of it."""

from __future__ import annotations

import numpy as np
import yaml
from skyfield.api import EarthSatellite

from speclight.orbit import load_timescale, time_from_utc
from speclight.scenario import parse_scenario
from speclight.scenario.builtin_examples import example_text
from speclight.simulation.geometry_stage import Geometry, scenario_geometry

#: The box-wing example's pass (Calsphere 2's element set over Stuttgart), every 30 s.
PASS_TIME = {"start": "2019-08-30T02:20:00Z", "stop": "2019-08-30T02:29:00Z", "step_s": 30.0}


def pass_scenario(attitude: dict, **changes: object) -> dict:
    """The box-wing example as a geometry-only scenario (no target) with ``attitude``."""
    d = yaml.safe_load(example_text("box-wing"))
    d.pop("target")
    d["time"] = dict(PASS_TIME)
    d["observer"]["light_time"] = False  # skyfield's positions below are geometric
    d["attitude"] = attitude
    d.update(changes)
    return d


def pass_geometry(attitude: dict, **changes: object) -> Geometry:
    """Geometry of the pass with the given attitude section."""
    d = pass_scenario(attitude, **changes)
    return scenario_geometry(parse_scenario(yaml.safe_dump(d), source="test"))


def skyfield_pass(geo: Geometry):
    """``(satellite, t)``: skyfield's SGP4 satellite of the example's TLE, the pass epochs."""
    lines = yaml.safe_load(example_text("box-wing"))["orbit"]["tle"].strip().split("\n")
    sat = EarthSatellite(lines[1], lines[2], lines[0], load_timescale())
    return sat, time_from_utc(geo.time_utc)


def unit(v: np.ndarray) -> np.ndarray:
    """Rows scaled to unit length."""
    return v / np.linalg.norm(v, axis=-1, keepdims=True)
