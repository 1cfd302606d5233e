"""Where to point: topocentric RA/Dec, angular rate and the Sun's elevation, against skyfield.

The references are skyfield's own (Rhodes, skyfield "Positions"): the astrometric position
``(earth + site).at(t).observe(earth + satellite)`` (light time in the barycentric frame),
its ``.radec()`` (ICRS) and ``.apparent().radec(epoch='date')``, the Sun's
``.observe(sun).apparent().altaz()``, and the angular rate as a central difference of the
astrometric RA/Dec. speclight computes them from its own geometry (SGP4 + its own TEME ->
GCRS, light time solved in the GCRS, aberration, precession-nutation).
"""

from __future__ import annotations

import numpy as np
import pytest
from numpy.typing import NDArray
from skyfield.api import EarthSatellite, wgs84

import speclight
from speclight.constants import C_M_S
from speclight.orbit.timescale import load_ephemeris, load_timescale, time_from_utc
from speclight.scenario import LoadedScenario, load_example
from speclight.simulation.geometry_stage import scenario_geometry

ARCSEC = 1.0 / 3600.0
#: Fastest barycentric speed of the Earth (perihelion, 30.29 km/s) [m s-1].
V_EARTH_MAX_M_S = 30.3e3
#: Fastest LEO speed [m s-1].
V_TARGET_MAX_M_S = 7.9e3
#: speclight and skyfield positions agree to 1 mm (tests/orbit/test_orbit_tle.py)
#: [m], at a range of no less than 1000 km in these passes [m].
POSITION_AGREEMENT_M, MIN_RANGE_M = 1e-3, 1.0e6
#: speclight solves the light time in the GCRS, skyfield in the barycentric frame: the two
#: differ by V_earth / c of it, which moves the Earth's term V_earth tau by (V_earth / c)^2
#: of the range and the target by v V_earth / c^2 of it; Earth's light deflection, which
#: skyfield adds, is < 1.4e-9 rad (2 GM / (c^2 R)); the positions add their agreement.
RADEC_TOLERANCE_DEG = np.degrees(
    (V_EARTH_MAX_M_S / C_M_S) ** 2
    + V_TARGET_MAX_M_S * V_EARTH_MAX_M_S / C_M_S**2
    + 1.4e-9
    + POSITION_AGREEMENT_M / MIN_RANGE_M
)
#: speclight's Sun is the geocentric apparent one seen from the site: the diurnal
#: aberration skyfield adds is at most 465 m s-1 / c = 0.32 arcsec.
SUN_ELEVATION_TOLERANCE_DEG = 0.32 * ARCSEC
#: Half step of skyfield's central difference [s], and its error relative to the rate: the
#: truncation (measured: 2.5e-5 at 0.2 s, falling as the step squared: 6e-7 at 0.03 s) and
#: skyfield's direction noise (its barycentric vectors of 1 au in float64; measured: 1.5e-5
#: at 2 ms, falling as 1 / step: 1e-6 at 0.03 s), doubled for the other passes.
RATE_HALF_STEP_S = 0.03
RATE_TOLERANCE = 2 * (6e-7 + 1e-6)


def _skyfield(loaded: LoadedScenario) -> tuple[EarthSatellite, object]:
    sc = loaded.scenario
    assert sc.orbit.tle is not None
    lines = sc.orbit.tle.strip().splitlines()
    sat = EarthSatellite(lines[-2], lines[-1], ts=load_timescale())
    obs = sc.observer
    return sat, wgs84.latlon(obs.latitude_deg, obs.longitude_deg, elevation_m=obs.altitude_m)


def _separation_deg(ra1: NDArray, dec1: NDArray, ra2: NDArray, dec2: NDArray) -> NDArray:
    def unit(ra: NDArray, dec: NDArray) -> NDArray:
        a, d = np.radians(ra), np.radians(dec)
        return np.stack([np.cos(d) * np.cos(a), np.cos(d) * np.sin(a), np.sin(d)], axis=1)

    u, v = unit(ra1, dec1), unit(ra2, dec2)
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(u, v), axis=1), np.sum(u * v, axis=1)))


def _astrometric(loaded: LoadedScenario, time_utc: NDArray) -> object:
    sat, site = _skyfield(loaded)
    eph = load_ephemeris()
    return (eph["earth"] + site).at(time_from_utc(time_utc)).observe(eph["earth"] + sat)


@pytest.mark.parametrize(("name", "every"), [("calsphere", 12), ("lcs1", 20)])
def test_radec_and_sun_elevation_match_skyfield(name: str, every: int) -> None:
    # the whole window (the interpolated precession-nutation and Earth velocity of long
    # runs), compared at every `every`-th epoch
    loaded = load_example(name)
    geo = scenario_geometry(loaded)
    idx = np.arange(0, geo.time_utc.size, every)
    astro = _astrometric(loaded, geo.time_utc[idx])
    ra, dec, _ = astro.radec()
    sep = _separation_deg(geo.sky.ra_deg[idx], geo.sky.dec_deg[idx], ra._degrees, dec.degrees)
    assert np.all(sep < RADEC_TOLERANCE_DEG), sep.max() / ARCSEC
    ra_app, dec_app, _ = astro.apparent().radec(epoch="date")
    sep = _separation_deg(
        geo.sky.ra_apparent_deg[idx],
        geo.sky.dec_apparent_deg[idx],
        ra_app._degrees,
        dec_app.degrees,
    )
    assert np.all(sep < RADEC_TOLERANCE_DEG), sep.max() / ARCSEC
    eph = load_ephemeris()
    _, site = _skyfield(loaded)
    sun = (eph["earth"] + site).at(time_from_utc(geo.time_utc[idx])).observe(eph["sun"])
    alt = sun.apparent().altaz()[0].degrees
    assert np.allclose(geo.sun_elevation_deg[idx], alt, rtol=0, atol=SUN_ELEVATION_TOLERANCE_DEG)


def test_angular_rate_matches_skyfields_central_difference() -> None:
    loaded = load_example("calsphere")
    geo = scenario_geometry(loaded)
    idx = np.arange(0, geo.time_utc.size, 16)
    step = np.timedelta64(int(RATE_HALF_STEP_S * 1e9), "ns")
    ra1, dec1, _ = _astrometric(loaded, geo.time_utc[idx] - step).radec()
    ra2, dec2, _ = _astrometric(loaded, geo.time_utc[idx] + step).radec()
    dra = (np.radians(ra2._degrees - ra1._degrees) + np.pi) % (2 * np.pi) - np.pi
    _, dec, _ = _astrometric(loaded, geo.time_utc[idx]).radec()
    east = np.degrees(dra * np.cos(dec.radians)) / (2 * RATE_HALF_STEP_S)
    north = (dec2.degrees - dec1.degrees) / (2 * RATE_HALF_STEP_S)
    total = np.hypot(east, north)
    sky = geo.sky
    assert np.allclose(sky.angular_rate_deg_s[idx], total, rtol=RATE_TOLERANCE, atol=0)
    assert np.allclose(sky.ra_cos_dec_rate_deg_s[idx], east, rtol=0, atol=RATE_TOLERANCE * total)
    assert np.allclose(sky.dec_rate_deg_s[idx], north, rtol=0, atol=RATE_TOLERANCE * total)


def test_few_epochs_and_no_light_time_give_the_geometric_direction() -> None:
    # the exact (per-epoch skyfield) path of fewer than 200 epochs; without light time the
    # astrometric position is the geometric one at the epoch: skyfield's (sat - site).at(t)
    loaded = speclight.with_overrides(load_example("calsphere"), {"observer.light_time": False})
    grid = np.datetime64("2020-02-29T21:13:00", "ns") + np.arange(0, 480, 60) * np.timedelta64(
        1, "s"
    )
    geo = scenario_geometry(loaded, time_utc=grid)
    sat, site = _skyfield(loaded)
    ra, dec, _ = (sat - site).at(time_from_utc(grid)).radec()
    sep = _separation_deg(geo.sky.ra_deg, geo.sky.dec_deg, ra._degrees, dec.degrees)
    assert np.all(sep < np.degrees(POSITION_AGREEMENT_M / MIN_RANGE_M) + 1e-12)
