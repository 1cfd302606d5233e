"""Daylight epochs (the Sun above ``observer.max_sun_elevation_deg`` at the site) are flagged
``daylight`` and left unrendered, as epochs below the minimum elevation are (issue 22 item 4).

Calsphere 4A passes over Stuttgart on 2020-03-01 from 08:17 to 08:29 UTC, sunlit, with the
Sun 19 to 21 deg high there (skyfield: tests/orbit/test_orbit_sky_position.py checks the
Sun's elevation against it), and on 2020-02-29 from 21:04 to 21:18 UTC with the Sun 37 to
39 deg below the horizon.
"""

from __future__ import annotations

import numpy as np
import pytest

import speclight
from speclight import schema as v
from speclight.scenario import load_example
from speclight.simulation import simulate

NOON_PASS = {"time.start": "2020-03-01T08:17:00Z", "time.stop": "2020-03-01T08:29:00Z"}


def _run(overrides: dict[str, object]) -> speclight.simulation.SimulationResult:
    loaded = speclight.with_overrides(
        load_example("calsphere"), {"time.step_s": 60.0, "render.resolution_px": 32, **overrides}
    )
    return simulate(loaded)


def test_daylight_epochs_are_flagged_and_not_rendered() -> None:
    result = _run(NOON_PASS)
    ds = result.dataset
    flags = ds["flags"].values
    high = (flags & (v.FLAG_BELOW_MIN_ELEVATION | v.FLAG_ORBIT_FAILED)) == 0
    assert high.sum() >= 10 and (ds["sunlit"].values[high] > 0).all()
    assert (ds["sun_elevation_site"].values > 15.0).all()
    assert ((flags & v.FLAG_DAYLIGHT) != 0).all()
    assert np.isnan(ds["intensity"].values).all()  # as below the minimum elevation
    assert np.isnan(ds["count_rate"].values).all()
    assert "flag daylight" in " ".join(result.notes)
    assert result.notes[0].startswith(
        f"{flags.size} epochs: {int(high.sum())} above the minimum elevation (10 deg), 0 of them "
        "in a dark sky (the Sun below -6 deg), 0 of those"
    )
    assert "daylight" in ds["flags"].attrs["flag_meanings"].split()
    assert float(ds["max_sun_elevation"]) == -6.0 and ds.attrs["max_sun_elevation_deg"] == -6.0


def test_a_limit_of_90_deg_renders_daylight() -> None:
    result = _run({**NOON_PASS, "observer.max_sun_elevation_deg": 90.0})
    ds = result.dataset
    flags = ds["flags"].values
    assert not (flags & v.FLAG_DAYLIGHT).any()
    seen = (flags & v.NOT_OBSERVABLE) == 0
    assert seen.sum() >= 10
    assert (ds["count_rate"].values[seen] > 0).all()


@pytest.mark.parametrize("limit", [-6.0, -39.5])
def test_the_progress_line_counts_observable_epochs(limit: float) -> None:
    # the night pass: a limit of -39.5 deg makes the part of the pass before the Sun sinks
    # below it daylight
    result = _run({"observer.max_sun_elevation_deg": limit})
    ds = result.dataset
    flags = ds["flags"].values
    high = (flags & (v.FLAG_BELOW_MIN_ELEVATION | v.FLAG_ORBIT_FAILED)) == 0
    dark = high & (ds["sun_elevation_site"].values <= limit)
    seen = (flags & v.NOT_OBSERVABLE) == 0
    assert ((flags & v.FLAG_DAYLIGHT) != 0).tolist() == (
        ds["sun_elevation_site"].values > limit
    ).tolist()
    assert result.notes[0] == (
        f"{flags.size} epochs: {int(high.sum())} above the minimum elevation (10 deg), "
        f"{int(dark.sum())} of them in a dark sky (the Sun below {limit:g} deg), "
        f"{int(seen.sum())} of those with the target sunlit (observable)"
    )
    assert np.isfinite(ds["count_rate"].values[seen]).all()
    assert np.isnan(ds["count_rate"].values[high & ~dark]).all()
    if limit == -39.5:
        assert 0 < dark.sum() < high.sum()
