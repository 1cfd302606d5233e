"""Topocentric geometry and the Sun against astropy, an independent chain.

Reference: astropy 8 (ERFA). The satellite is propagated with the ``sgp4`` library
directly (TEME), then astropy ``TEME -> ITRS`` (GMST 1982 + polar motion) and the
topocentric ``ITRS -> AltAz`` transform (geometric: the ITRS vector is made topocentric
first, as astropy's documentation recommends for satellites). Earth orientation comes
from astropy-iers-data (offline), ours from skyfield-data's finals2000A.all: the two
tables are different files.
"""

from __future__ import annotations

import astropy.units as u
import numpy as np
import pytest
from astropy.coordinates import (
    GCRS,
    ITRS,
    TEME,
    AltAz,
    CartesianRepresentation,
    EarthLocation,
    get_sun,
)
from astropy.time import Time as ATime
from astropy.utils import iers
from sgp4.api import Satrec

from speclight.orbit import (
    Site,
    earth_orientation,
    parse_tle,
    site_position_gcrs_m,
    sun_position_gcrs_m,
    tle_position_gcrs_m,
    topocentric,
)

iers.conf.auto_download = False
iers.conf.auto_max_age = None

L1 = "1 01361U 65034C   20199.53569372  .00000028  00000-0  25492-2 0  9994"
L2 = "2 01361  32.1395 267.1291 0005455 248.0922 111.8996  9.89297492995906"
STUTTGART = Site(latitude_deg=48.7822, longitude_deg=9.1967, altitude_m=355.0)

# Both chains rotate TEME -> ITRS by GMST 1982 and polar motion. Their UT1-UTC and pole
# tables agree to ~0.05 ms and ~0.5 mas for 2020 (measured values), i.e. a rotation of
# <= 1 mas: 4.5 cm at the 9,000 km of LCS 1 from the Earth's axis.
RANGE_TOLERANCE_M = 0.05
ANGLE_TOLERANCE_ARCSEC = 0.01
# Site position in GCRS: skyfield uses IAU 2000A equinox-based, astropy IAU 2006/2000A
# CIO-based precession-nutation; they differ by < 1 mas (3 cm at the Earth's radius).
SITE_TOLERANCE_M = 0.05
# Sun: both apparent geocentric (light time + annual aberration). astropy's get_sun uses
# ERFA epv00 for the Earth (~5 km, 0.007" at 1 au) instead of DE421.
SUN_DIRECTION_TOLERANCE_ARCSEC = 0.1
SUN_DISTANCE_TOLERANCE_M = 5_000.0
# Refraction: Bennett's formula is good to 0.07' = 4.2" (Bennett 1982); ERFA's refco
# model to ~1" above 15 deg elevation (SOFA documentation of iauRefco).
REFRACTION_TOLERANCE_ARCSEC = 5.2


@pytest.fixture(scope="module")
def pass_epochs() -> np.ndarray:
    t = np.datetime64("2020-07-17T12:00:00", "ns") + np.arange(0, 86400, 60) * np.timedelta64(
        1, "s"
    )
    tle = parse_tle(f"{L1}\n{L2}")
    r, _ = tle_position_gcrs_m(tle, t)
    el = topocentric(STUTTGART, r, t).elevation_deg
    visible = np.flatnonzero(el > 0.0)
    assert visible.size > 50  # LCS 1 passes over Stuttgart on that day
    # Visible epochs plus some below the horizon.
    return t[np.concatenate([visible[::4], np.flatnonzero(el < -30.0)[::200]])]


def _astropy_time(t: np.ndarray) -> ATime:
    return ATime(t.astype("datetime64[us]").astype(str), scale="utc")


def test_range_azimuth_elevation_match_astropy(pass_epochs: np.ndarray) -> None:
    t = pass_epochs
    at = _astropy_time(t)
    sat = Satrec.twoline2rv(L1, L2)
    err, r_teme_km, _ = sat.sgp4_array(at.jd1, at.jd2)
    assert not err.any()
    loc = EarthLocation.from_geodetic(9.1967 * u.deg, 48.7822 * u.deg, 355.0 * u.m)
    teme = TEME(CartesianRepresentation(r_teme_km.T * u.km), obstime=at)
    itrs_geo = teme.transform_to(ITRS(obstime=at))
    topo = itrs_geo.cartesian - loc.get_itrs(at).cartesian
    aa = ITRS(topo, obstime=at, location=loc).transform_to(AltAz(obstime=at, location=loc))

    r, ok = tle_position_gcrs_m(parse_tle(f"{L1}\n{L2}"), t)
    ours = topocentric(STUTTGART, r, t)
    assert ok.all()
    assert np.abs(ours.range_m - aa.distance.m).max() < RANGE_TOLERANCE_M
    d_az = (ours.azimuth_deg - aa.az.deg + 180.0) % 360.0 - 180.0
    d_az_sky = d_az * np.cos(np.radians(aa.alt.deg)) * 3600.0
    assert np.abs(d_az_sky).max() < ANGLE_TOLERANCE_ARCSEC
    assert np.abs(ours.elevation_deg - aa.alt.deg).max() * 3600.0 < ANGLE_TOLERANCE_ARCSEC


def test_site_gcrs_matches_astropy(pass_epochs: np.ndarray) -> None:
    at = _astropy_time(pass_epochs)
    loc = EarthLocation.from_geodetic(9.1967 * u.deg, 48.7822 * u.deg, 355.0 * u.m)
    ref = loc.get_gcrs(at).cartesian.xyz.to(u.m).value.T
    ours = site_position_gcrs_m(STUTTGART, pass_epochs)
    assert np.linalg.norm(ours - ref, axis=1).max() < SITE_TOLERANCE_M


def test_sun_matches_astropy_get_sun(pass_epochs: np.ndarray) -> None:
    at = _astropy_time(pass_epochs)
    ref = get_sun(at).transform_to(GCRS(obstime=at)).cartesian.xyz.to(u.m).value.T
    ours = sun_position_gcrs_m(pass_epochs)
    cos = np.sum(ours * ref, 1) / np.linalg.norm(ours, axis=1) / np.linalg.norm(ref, axis=1)
    sep_arcsec = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))) * 3600.0
    assert sep_arcsec.max() < SUN_DIRECTION_TOLERANCE_ARCSEC
    d_dist = np.linalg.norm(ours, axis=1) - np.linalg.norm(ref, axis=1)
    assert np.abs(d_dist).max() < SUN_DISTANCE_TOLERANCE_M


def test_refraction_matches_astropy_above_15_deg() -> None:
    t = np.array(["2020-07-17T20:00:00"], dtype="datetime64[ns]")
    at = ATime("2020-07-17T20:00:00", scale="utc")
    loc = EarthLocation.from_geodetic(9.1967 * u.deg, 48.7822 * u.deg, 355.0 * u.m)
    site_itrs = STUTTGART.position_itrs_m
    for el_true in (15.0, 30.0, 45.0, 70.0):
        # A target 1,000 km away at azimuth 0 and the given true elevation.
        e = np.radians(el_true)
        enu = 1.0e6 * np.array([0.0, np.cos(e), np.sin(e)])
        r_itrs = site_itrs + enu @ STUTTGART.enu_matrix
        aa_true = AltAz(
            CartesianRepresentation(*enu[[1, 0, 2]] * u.m),  # astropy AltAz: x north, y east
            obstime=at,
            location=loc,
        )
        observed = aa_true.transform_to(
            AltAz(
                obstime=at,
                location=loc,
                pressure=1010.0 * u.hPa,
                temperature=10.0 * u.deg_C,
                relative_humidity=0.0,
                obswl=0.55 * u.um,
            )
        )
        eo = earth_orientation(t)
        r_gcrs = eo.itrs_to_gcrs(r_itrs[None, :])
        ours = topocentric(STUTTGART, r_gcrs, t, refraction=True, orientation=eo)
        assert abs(ours.elevation_deg[0] - observed.alt.deg) * 3600.0 < (
            REFRACTION_TOLERANCE_ARCSEC
        ), el_true
