"""Where ``speclight compare`` puts the target: the scenario's orbit, or with
``orbit: {observed: true}`` the positions the rows saw, one trajectory per ``object``.

The rows are split into groups that share one trajectory: all rows where the scenario has
an orbit or the file has no ``object`` column (as before objects were known), else the
layers of :func:`speclight.orbit.observed_objects.object_layers` (objects whose rows do
not overlap in time). A site's simulation covers all its groups: their geometries are
joined along the epochs (:func:`join_geometries`) and rendered in one run.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, is_dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight import orbit
from speclight.constants import C_M_S
from speclight.errors import InputError
from speclight.estimate.inputs.observations import FIELD, Observations
from speclight.orbit.observed_objects import object_layers
from speclight.orbit.observed_position import (
    observed_trajectory,
    place_target_gcrs_m,
    range_from_height_m,
)
from speclight.orbit.orbit_sources import Trajectory
from speclight.orbit.timescale import time_from_utc
from speclight.scenario import LoadedScenario
from speclight.simulation.observed_track import VELOCITY_HALF_STEP_S

F64 = NDArray[np.float64]
#: Slack of an object's time window beyond its light time and the velocity's half step [s]:
#: the light-time iteration moves the emission time by < 1 ms between its steps.
WINDOW_SLACK_S = 1.0


@dataclass(frozen=True)
class RowGroup:
    """Rows that share one trajectory: ``trajectory`` None means the scenario's orbit."""

    rows: NDArray[np.intp]
    trajectory: Trajectory | None


def row_groups(loaded: LoadedScenario, obs: Observations) -> list[RowGroup]:
    """The groups of rows that share a trajectory (see the module docstring); rows of an
    object without any placed position are in none (their orbit failed)."""
    every = np.arange(obs.time_utc.size, dtype=np.intp)
    if not loaded.scenario.orbit.observed:
        return [RowGroup(every, None)]
    emitted, r, delay_s = _placed(loaded, obs)
    if obs.object_name is None:  # one target: one trajectory through every row
        return [RowGroup(every, observed_trajectory(emitted, r))]
    _, index = obs.object_index()
    margin_s = float(np.nanmax(delay_s, initial=0.0)) + VELOCITY_HALF_STEP_S + WINDOW_SLACK_S
    return [RowGroup(la.rows, la.trajectory) for la in object_layers(emitted, r, index, margin_s)]


def single_epoch_objects(loaded: LoadedScenario, obs: Observations) -> list[str]:
    """With ``orbit: {observed: true}``, the objects seen at one epoch only: their
    trajectory is one position without a velocity, so an attitude that needs the velocity
    (``nadir``, a pointing profile with a ``velocity`` or ``orbit_normal`` constraint) is
    undefined there (flag ``attitude_undefined``)."""
    if not loaded.scenario.orbit.observed or obs.object_name is None:
        return []
    names, index = obs.object_index()
    order = np.argsort(index, kind="stable")
    bounds = np.searchsorted(index[order], np.arange(len(names) + 1))
    return [
        name
        for j, name in enumerate(names)
        if np.unique(obs.time_utc[order[bounds[j] : bounds[j + 1]]]).size == 1
    ]


def _placed(loaded: LoadedScenario, obs: Observations) -> tuple[NDArray[np.datetime64], F64, F64]:
    """Each row's emission epoch (UTC), GCRS position [m] (NaN: not placed) and light
    time [s] (0 with ``observer.light_time: false``)."""
    if not obs.has_positions:
        bad = ~(
            np.isfinite(obs.elevation_deg) & (np.isfinite(obs.range_m) | np.isfinite(obs.height_m))
        )
        line = int(obs.line[np.flatnonzero(bad)[0]])
        raise InputError(
            f"line {line}: the scenario has orbit: {{observed: true}}, so every row must give "
            "where the target was seen: elevation_deg, azimuth_deg and range_m (or height_m)",
            source=obs.source,
            field=FIELD,
        )
    n = obs.time_utc.size
    r = np.full((n, 3), np.nan)
    rng = obs.range_m.copy()
    for (lat, lon, alt), idx in obs.site_groups():
        site = orbit.Site(lat, lon, alt)
        need = idx[~np.isfinite(rng[idx])]
        if need.size:
            rng[need] = range_from_height_m(
                site, obs.azimuth_deg[need], obs.elevation_deg[need], obs.height_m[need]
            )
        t = time_from_utc(obs.time_utc[idx])
        r[idx] = place_target_gcrs_m(
            site, t, obs.azimuth_deg[idx], obs.elevation_deg[idx], rng[idx]
        )
    delay_s = np.zeros(n)
    emitted = obs.time_utc.copy()
    if loaded.scenario.observer.light_time:
        delay_s = np.nan_to_num(rng) / C_M_S
        emitted = obs.time_utc - np.rint(delay_s * 1e9).astype("timedelta64[ns]")
    return emitted, r, delay_s


def join_geometries(parts: list[Any]) -> Any:
    """Geometries (:class:`~speclight.simulation.geometry_stage.Geometry`) of one site
    joined along their epochs, in the order given: every per-epoch array concatenated
    (nested dataclasses, such as the sky position, field by field)."""
    if len(parts) == 1:
        return parts[0]
    first = parts[0]
    assert is_dataclass(first) and not isinstance(first, type)
    joined = {
        f.name: (
            join_geometries([getattr(p, f.name) for p in parts])
            if is_dataclass(getattr(first, f.name))
            else np.concatenate([getattr(p, f.name) for p in parts])
        )
        for f in fields(first)
    }
    return type(first)(**joined)
