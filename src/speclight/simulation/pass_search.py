"""``speclight passes``: the passes of a scenario's target over its site, with the pipeline's
own geometry (any orbit source, light time, refraction, the conical Earth shadow).

Rise and set are crossings of ``observer.min_elevation_deg``; the dark sky is the Sun at or
below ``observer.max_sun_elevation_deg`` at the site; observable is sunlit and dark at once,
the epochs ``speclight simulate`` renders (docs/passes.md).
"""

from __future__ import annotations

from dataclasses import dataclass
from datetime import UTC, datetime, timedelta

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.orbit.orbit_sources import no_position_message
from speclight.orbit.pass_finder import Pass, PassSamples, find_passes
from speclight.orbit.staleness import warn_past_tables
from speclight.orbit.timescale import time_from_utc
from speclight.scenario import LoadedScenario
from speclight.scenario.sections_geometry import FIRST_EPOCH_UTC, LAST_EPOCH_UTC
from speclight.simulation.geometry_stage import scenario_trajectory
from speclight.simulation.observed_track import observed_track

#: Grid step of the search [s]: a LEO pass lasts several minutes, a shadow or twilight
#: limit follows the last by more than a minute; maxima are refined however short.
SEARCH_STEP_S = 60.0
#: Accuracy of every event time [s].
TOLERANCE_S = 1e-3
#: Longest search window [days] (86,400 grid epochs at the step above).
MAX_WINDOW_DAYS = 60.0


@dataclass(frozen=True)
class PassSearch:
    """The passes found in a window, and the limits used.

    Attributes
    ----------
    start_utc, end_utc
        The search window, UTC.
    min_elevation_deg, max_sun_elevation_deg
        The scenario's limits [deg].
    passes
        The passes, in time order.
    """

    start_utc: np.datetime64
    end_utc: np.datetime64
    min_elevation_deg: float
    max_sun_elevation_deg: float
    passes: list[Pass]


def parse_utc(text: str, field: str) -> datetime:
    """An ISO 8601 time (``Z``, an offset, or none for UTC) as an aware UTC ``datetime``."""
    try:
        value = datetime.fromisoformat(text.strip())
    except ValueError:
        raise InputError(
            f"{field} = {text!r} is not an ISO 8601 time; give e.g. 2020-02-29T21:00:00Z",
            field=field,
        ) from None
    return value.replace(tzinfo=UTC) if value.tzinfo is None else value.astimezone(UTC)


def _window(
    loaded: LoadedScenario, start_utc: datetime | None, end_utc: datetime | None
) -> tuple[datetime, datetime]:
    start = start_utc if start_utc is not None else loaded.scenario.time.start
    end = end_utc if end_utc is not None else loaded.scenario.time.stop
    if not end > start:
        raise InputError(
            f"the search window ends ({end.isoformat()}) before it starts "
            f"({start.isoformat()}): give an end_utc (--end) after start_utc (--start)",
            source=loaded.source,
            field="end_utc",
        )
    if start < FIRST_EPOCH_UTC or end > LAST_EPOCH_UTC:
        raise InputError(
            f"the window {start.isoformat()} .. {end.isoformat()} is outside what the shipped "
            f"Sun ephemeris (JPL DE421) covers; accepted: {FIRST_EPOCH_UTC.date()} to "
            f"{LAST_EPOCH_UTC.date()} UTC",
            source=loaded.source,
            field="start_utc",
        )
    if end - start > timedelta(days=MAX_WINDOW_DAYS):
        days = (end - start) / timedelta(days=1)
        raise InputError(
            f"the search window is {days:.1f} days long; at most {MAX_WINDOW_DAYS:g} days "
            f"({MAX_WINDOW_DAYS * 86400 / SEARCH_STEP_S:,.0f} epochs at {SEARCH_STEP_S:g} s) "
            "are searched at once: split it",
            source=loaded.source,
            field="end_utc",
        )
    return start, end


def scenario_passes(
    loaded: LoadedScenario, start_utc: datetime | None = None, end_utc: datetime | None = None
) -> PassSearch:
    """Rise, culmination and set of every pass of the scenario's target over its site.

    Parameters
    ----------
    loaded
        A validated scenario (its ``orbit`` and ``observer``; nothing else is used).
    start_utc, end_utc
        The search window (aware or UTC ``datetime``); default the scenario's ``time``.

    Returns
    -------
    PassSearch
    """
    sc = loaded.scenario
    start, end = _window(loaded, start_utc, end_utc)
    t0 = np.datetime64(start.replace(tzinfo=None), "ns")
    t1 = np.datetime64(end.replace(tzinfo=None), "ns")
    warn_past_tables(np.array([t0, t1]))
    trajectory = scenario_trajectory(loaded, np.array([t0, t1]))
    step = np.timedelta64(int(SEARCH_STEP_S * 1e9), "ns")
    _, ok = trajectory(time_from_utc(np.arange(t0, t1 + step, step)))
    if not np.any(ok):
        raise InputError(
            no_position_message(sc.orbit.model_dump()), source=loaded.source, field="start_utc"
        )

    def sample(time_utc: NDArray[np.datetime64]) -> PassSamples:
        track = observed_track(sc.observer, time_utc, trajectory)
        g = track.geometry
        return PassSamples(
            elevation_deg=np.where(track.ok, g.elevation_deg, np.nan),
            azimuth_deg=g.azimuth_deg,
            range_m=g.range_m,
            sun_elevation_deg=g.sun_elevation_deg,
            sunlit_fraction=g.sunlit_fraction,
        )

    obs = sc.observer
    passes = find_passes(
        sample,
        t0,
        t1,
        obs.min_elevation_deg,
        obs.max_sun_elevation_deg,
        step_s=SEARCH_STEP_S,
        tolerance_s=TOLERANCE_S,
    )
    return PassSearch(t0, t1, obs.min_elevation_deg, obs.max_sun_elevation_deg, passes)
