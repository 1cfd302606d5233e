"""``speclight passes`` against skyfield's ``EarthSatellite.find_events`` and the pipeline.

References: skyfield's pass finder (Rhodes, skyfield ``sgp4lib.find_events``: rise, culmination
and set located to half a second) and skyfield's topocentric altitude itself, which brackets
every event sharply; for the sunlit and dark-sky parts, the pipeline's own per-epoch flags
(``in_earth_shadow``, ``daylight``) and skyfield's altitude of the Sun. A TLE and a CPF file
(the same orbit, tabulated: src/speclight/data/cpf/README.md) go through the one search.
"""

from __future__ import annotations

from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pytest
from numpy.typing import NDArray
from skyfield.api import EarthSatellite, wgs84

import speclight
from speclight import schema as v
from speclight.orbit.pass_finder import Pass
from speclight.orbit.timescale import load_ephemeris, load_timescale, time_from_utc
from speclight.scenario import LoadedScenario, load_example
from speclight.simulation.geometry_stage import scenario_geometry
from speclight.simulation.pass_search import TOLERANCE_S, scenario_passes

#: skyfield's find_events locates events to half a second (its ``half_second`` epsilon).
FIND_EVENTS_EPSILON_S = 0.5
#: Our events are the middle of a bracket shorter than TOLERANCE_S: within half of it of
#: the crossing. Position differences (1 mm for SGP4, 1 cm for the CPF's interpolation,
#: tests/orbit/test_orbit_cpf.py) move a crossing by < 1e-4 s at the elevation rates here
#: (> 0.005 deg/s at 10 deg, range < 6000 km): an event brackets skyfield's crossing +-TOLERANCE_S.
BRACKET_S = TOLERANCE_S
#: The Sun's elevation here differs from skyfield's by the diurnal aberration, <= 0.32".
SUN_ELEVATION_AGREEMENT_DEG = 0.32 / 3600.0
CPF = Path(speclight.__file__).parent / "data/cpf/lcs1_20201127_speclight_sgp4.cpf"


def _satellite(name: str) -> tuple[EarthSatellite, object, LoadedScenario]:
    loaded = load_example(name)
    sc = loaded.scenario
    assert sc.orbit.tle is not None
    lines = sc.orbit.tle.strip().splitlines()
    obs = sc.observer
    site = wgs84.latlon(obs.latitude_deg, obs.longitude_deg, elevation_m=obs.altitude_m)
    return EarthSatellite(lines[-2], lines[-1], ts=load_timescale()), site, loaded


def _altitude(sat: EarthSatellite, site: object, t: NDArray[np.datetime64]) -> NDArray:
    """skyfield's geometric topocentric altitude [deg] (as find_events uses it)."""
    return (sat - site).at(time_from_utc(t)).altaz()[0].degrees


def _seconds(a: np.datetime64, b: object) -> float:
    return abs(float((a - np.datetime64(b.utc_datetime().replace(tzinfo=None), "ns")) / 1e9))


def _check_against_find_events(
    passes: list[Pass], sat: EarthSatellite, site: object, t0: datetime, t1: datetime
) -> None:
    ts = load_timescale()
    t, events = sat.find_events(site, ts.from_datetime(t0), ts.from_datetime(t1), 10.0)
    rises, culms, sets = t[events == 0], t[events == 1], t[events == 2]
    inside = [p for p in passes if not (p.rises_before_start or p.sets_after_end)]
    assert len(inside) >= 3 and len(rises) >= len(inside)
    step = np.timedelta64(int(BRACKET_S * 1e9), "ns")
    for p in inside:
        rise = min(rises, key=lambda r: _seconds(p.rise_utc, r))
        assert _seconds(p.rise_utc, rise) <= FIND_EVENTS_EPSILON_S + TOLERANCE_S
        culm = min(culms, key=lambda c: _seconds(p.culmination_utc, c))
        assert _seconds(p.culmination_utc, culm) <= FIND_EVENTS_EPSILON_S + TOLERANCE_S
        set_ = min(sets, key=lambda s: _seconds(p.set_utc, s))
        assert _seconds(p.set_utc, set_) <= FIND_EVENTS_EPSILON_S + TOLERANCE_S
        # sharper: skyfield's own altitude crosses 10 deg inside +-BRACKET_S of our events
        alt = _altitude(sat, site, np.array([p.rise_utc - step, p.rise_utc + step]))
        assert alt[0] < 10.0 < alt[1]
        alt = _altitude(sat, site, np.array([p.set_utc - step, p.set_utc + step]))
        assert alt[0] > 10.0 > alt[1]
        # and is highest at our culmination, as high as we say
        near = np.timedelta64(50, "ms")
        c = p.culmination_utc
        alt = _altitude(sat, site, np.array([c - near, c, c + near]))
        assert alt[1] > alt[0] and alt[1] > alt[2]
        assert abs(alt[1] - p.max_elevation_deg) < 1e-6


def test_tle_passes_match_find_events() -> None:
    sat, site, loaded = _satellite("calsphere")
    loaded = speclight.with_overrides(loaded, {"observer.light_time": False})  # as skyfield
    t0, t1 = datetime(2020, 2, 29, 12, tzinfo=UTC), datetime(2020, 3, 1, 12, tzinfo=UTC)
    _check_against_find_events(scenario_passes(loaded, t0, t1).passes, sat, site, t0, t1)


def test_cpf_passes_match_find_events_on_the_tle() -> None:
    sat, site, loaded = _satellite("lcs1")
    loaded = speclight.with_overrides(
        loaded, {"observer.light_time": False, "orbit": {"cpf_file": str(CPF)}}
    )
    t0, t1 = datetime(2020, 11, 27, 0, 10, tzinfo=UTC), datetime(2020, 11, 27, 23, 50, tzinfo=UTC)
    _check_against_find_events(scenario_passes(loaded, t0, t1).passes, sat, site, t0, t1)


def _inside(t: NDArray[np.datetime64], spans: tuple) -> NDArray[np.bool_]:
    out = np.zeros(t.size, dtype=bool)
    for a, b in spans:
        out |= (t >= a) & (t <= b)
    return out


def _near(t: NDArray[np.datetime64], spans: tuple) -> NDArray[np.bool_]:
    edge = np.timedelta64(int(TOLERANCE_S * 1e9), "ns")
    out = np.zeros(t.size, dtype=bool)
    for a, b in spans:
        out |= (np.abs(t - a) <= edge) | (np.abs(t - b) <= edge)
    return out


@pytest.mark.parametrize("max_sun_elevation_deg", [-23.9, -6.0])
def test_sunlit_and_dark_parts_match_the_pipelines_flags(max_sun_elevation_deg: float) -> None:
    # Calsphere 4A leaves the Earth's shadow during its 19:21-19:29 pass of 2020-02-29 while
    # the Sun sinks from -22.9 to -24.2 deg at Stuttgart: a dark-sky limit of -23.9 deg
    # starts the dark sky after the target is lit (observable = dark part), -6 leaves the
    # whole pass dark (observable = sunlit part).
    loaded = speclight.with_overrides(
        load_example("calsphere"), {"observer.max_sun_elevation_deg": max_sun_elevation_deg}
    )
    t0, t1 = datetime(2020, 2, 29, 19, 10, tzinfo=UTC), datetime(2020, 2, 29, 19, 40, tzinfo=UTC)
    (p,) = scenario_passes(loaded, t0, t1).passes
    grid = np.datetime64("2020-02-29T19:10", "ns") + np.arange(1801) * np.timedelta64(1, "s")
    geo = scenario_geometry(loaded, time_utc=grid)
    up = (geo.flags & v.FLAG_BELOW_MIN_ELEVATION) == 0
    lit = up & ((geo.flags & v.FLAG_IN_SHADOW) == 0)
    dark = up & ((geo.flags & v.FLAG_DAYLIGHT) == 0)
    seen = up & geo.observable & (geo.sunlit_fraction > 0)
    pass_span = ((p.rise_utc, p.set_utc),)
    edges = _near(grid, pass_span + p.sunlit + p.dark_sky)
    for mask, spans in [(up, pass_span), (lit, p.sunlit), (dark, p.dark_sky), (seen, p.observable)]:
        assert (mask == _inside(grid, spans))[~edges].all()
    assert p.sunlit and p.observable
    if max_sun_elevation_deg == -6.0:
        assert p.dark_sky == pass_span and p.observable == p.sunlit
    else:
        start = p.dark_sky[0][0]
        assert p.dark_sky == p.observable == ((start, p.set_utc),) and start > p.sunlit[0][0]
        eph = load_ephemeris()
        obs = loaded.scenario.observer
        site = eph["earth"] + wgs84.latlon(obs.latitude_deg, obs.longitude_deg, obs.altitude_m)
        one = np.timedelta64(1, "s")
        t = time_from_utc(np.array([start - one, start + one]))
        alt = site.at(t).observe(eph["sun"]).apparent().altaz()[0].degrees
        rate_deg_s = (alt[0] - alt[1]) / 2.0
        # skyfield's Sun crosses the limit within the bracket plus the aberration's shift
        shift = np.timedelta64(
            int((TOLERANCE_S + SUN_ELEVATION_AGREEMENT_DEG / rate_deg_s) * 1e9), "ns"
        )
        t = time_from_utc(np.array([start - shift, start + shift]))
        alt = site.at(t).observe(eph["sun"]).apparent().altaz()[0].degrees
        assert alt[0] > max_sun_elevation_deg > alt[1]
