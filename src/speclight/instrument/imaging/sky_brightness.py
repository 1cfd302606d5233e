"""Brightness of the sky behind the target: night sky, twilight and moonlight, V band.

Krisciunas & Schaefer (1991, PASP 103, 1033, doi:10.1086/132921; "K&S"):

* the moonless night sky (airglow, zodiacal light, faint stars) of zenith brightness
  ``B_zen`` grows toward the horizon as ``B_zen X 10^(-0.4 k (X - 1))`` (eq. 2), with
  ``X(Z) = (1 - 0.96 sin^2 Z)^(-1/2)`` (eq. 3) and ``k`` the V extinction [mag/airmass];
* moonlight scattered by the atmosphere, ``B_moon = f(rho) I* 10^(-0.4 k X(Z_m))
  [1 - 10^(-0.4 k X(Z))]`` (eq. 15) with the Moon's illuminance
  ``I* = 10^(-0.4 (3.84 + 0.026 |alpha| + 4e-9 alpha^4))`` (eq. 20; alpha the Moon's phase
  angle [deg]) and the scattering function ``f(rho) = 10^5.36 (1.06 + cos^2 rho) +
  10^(6.15 - rho/40)`` (eq. 21; rho the Moon-target angle [deg]; 6.2e7 / rho^2 within 10 deg,
  K&S sect. 3);
* brightness in nanolamberts and V surface brightness are related by
  ``B = 34.08 exp(20.7233 - 0.92104 V)`` (K&S eq. 1).

Twilight brightens the zenith by ``dV(h)`` magnitudes for a Sun at elevation
``-18 < h < -0.9`` deg, the polynomial that Thorstensen's *skycalc* fitted to Meinel &
Meinel's zenith twilight curve (*Sunsets, Twilights and Evening Skies*, 1983, p. 38; it
agrees with Ashburn 1952, JGR 57, 85): ``y = (-h - 9) / 9``,
``dV = ((2.0635175 y + 1.246602) y - 9.4084495) y + 6.132725``. Above h = -0.9 deg the sky
is held at that value (a daylight frame is not modelled). The sky's spectrum is taken flat
in f_nu across the bands (its V brightness in every band, as AB magnitudes).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

F64 = NDArray[np.float64]

#: Sun elevation below which twilight is over [deg] (astronomical twilight, K&S's polynomial
#: is 0.03 mag there).
NIGHT_SUN_ELEVATION_DEG = -18.0
#: Sun elevation above which the twilight polynomial is not defined [deg].
TWILIGHT_TOP_DEG = -0.9
#: Moon zenith distance beyond which the Moon adds nothing [deg] (below the horizon with
#: its radius and refraction).
MOON_SET_ZENITH_DEG = 90.8


def airmass_ks(zenith_deg: ArrayLike) -> F64:
    """K&S eq. 3: ``X = (1 - 0.96 sin^2 Z)^(-1/2)``."""
    s = np.sin(np.radians(np.clip(np.asarray(zenith_deg, dtype=np.float64), 0.0, 90.0)))
    return np.asarray(1.0 / np.sqrt(1.0 - 0.96 * s**2))


def nanolambert_from_v(v_mag_arcsec2: ArrayLike) -> F64:
    """K&S eq. 1: brightness [nL] of a V surface brightness [mag arcsec-2]."""
    return np.asarray(34.08 * np.exp(20.7233 - 0.92104 * np.asarray(v_mag_arcsec2)))


def v_from_nanolambert(b_nl: ArrayLike) -> F64:
    """The inverse of :func:`nanolambert_from_v`."""
    return np.asarray((20.7233 - np.log(np.asarray(b_nl, dtype=np.float64) / 34.08)) / 0.92104)


def twilight_brightening_mag(sun_elevation_deg: ArrayLike) -> F64:
    """How much brighter twilight makes the zenith [mag] (skycalc's polynomial)."""
    h = np.clip(np.asarray(sun_elevation_deg, dtype=np.float64), -90.0, TWILIGHT_TOP_DEG)
    y = (-h - 9.0) / 9.0
    dv = ((2.0635175 * y + 1.246602) * y - 9.4084495) * y + 6.132725
    return np.asarray(np.where(h > NIGHT_SUN_ELEVATION_DEG, np.maximum(dv, 0.0), 0.0))


def moon_scattering(separation_deg: ArrayLike) -> F64:
    """K&S eq. 21 (and 6.2e7 / rho^2 within 10 deg)."""
    rho = np.maximum(np.asarray(separation_deg, dtype=np.float64), 1e-3)
    far = 10.0**5.36 * (1.06 + np.cos(np.radians(rho)) ** 2) + 10.0 ** (6.15 - rho / 40.0)
    return np.asarray(np.where(rho > 10.0, far, 6.2e7 / rho**2))


@dataclass(frozen=True)
class SkyConditions:
    """Where the Sun and Moon are, seen from the site, each of shape (N,).

    Attributes
    ----------
    target_zenith_deg
        Zenith distance of the field [deg].
    sun_elevation_deg
        Elevation of the Sun [deg].
    moon_zenith_deg
        Zenith distance of the Moon [deg].
    moon_phase_angle_deg
        Sun-Moon-observer angle [deg] (0 full, 180 new).
    moon_separation_deg
        Angle between the Moon and the field [deg].
    """

    target_zenith_deg: F64
    sun_elevation_deg: F64
    moon_zenith_deg: F64
    moon_phase_angle_deg: F64
    moon_separation_deg: F64


def sky_v_mag_arcsec2(
    sky: SkyConditions,
    dark_zenith_v_mag_arcsec2: float = 21.587,
    extinction_v_mag_per_airmass: float = 0.172,
) -> F64:
    """V surface brightness of the sky at the field [mag arcsec-2] (K&S 1991 + twilight).

    Parameters
    ----------
    sky
        Sun, Moon and field geometry.
    dark_zenith_v_mag_arcsec2
        Moonless night sky at the zenith (K&S: 21.587, Mauna Kea).
    extinction_v_mag_per_airmass
        V extinction coefficient k (K&S: 0.172, Mauna Kea).
    """
    k = extinction_v_mag_per_airmass
    x = airmass_ks(sky.target_zenith_deg)
    zenith_v = dark_zenith_v_mag_arcsec2 - twilight_brightening_mag(sky.sun_elevation_deg)
    b_sky = nanolambert_from_v(zenith_v) * x * 10.0 ** (-0.4 * k * (x - 1.0))
    alpha = np.abs(np.asarray(sky.moon_phase_angle_deg, dtype=np.float64))
    illuminance = 10.0 ** (-0.4 * (3.84 + 0.026 * alpha + 4e-9 * alpha**4))
    moon_up = np.asarray(sky.moon_zenith_deg) < MOON_SET_ZENITH_DEG
    b_moon = (
        moon_scattering(sky.moon_separation_deg)
        * illuminance
        * 10.0 ** (-0.4 * k * airmass_ks(sky.moon_zenith_deg))
        * (1.0 - 10.0 ** (-0.4 * k * x))
    )
    return v_from_nanolambert(b_sky + np.where(moon_up, b_moon, 0.0))


def sky_conditions(
    time_utc: NDArray[np.datetime64],
    latitude_deg: float,
    longitude_deg: float,
    altitude_m: float,
    field_ra_deg: ArrayLike,
    field_dec_deg: ArrayLike,
    field_elevation_deg: ArrayLike,
    sun_elevation_deg: ArrayLike | None = None,
) -> SkyConditions:
    """Sun and Moon seen from the site at each epoch (skyfield, JPL DE421).

    The Moon's topocentric altitude (no refraction), its phase angle and its angle from
    the field (ICRS astrometric). ``sun_elevation_deg`` is the pipeline's
    ``sun_elevation_site`` where the dataset has it; else computed here.
    """
    from skyfield.api import wgs84

    from speclight.attitude.quaternion import unit_vector_from_radec
    from speclight.orbit.timescale import load_ephemeris, time_from_utc

    eph = load_ephemeris()
    earth, moon, sun = eph["earth"], eph["moon"], eph["sun"]
    site = earth + wgs84.latlon(latitude_deg, longitude_deg, elevation_m=altitude_m)
    t = time_from_utc(np.asarray(time_utc, dtype="datetime64[ns]"))
    seen = site.at(t).observe(moon)
    moon_alt = seen.apparent().altaz()[0].degrees
    moon_vec = seen.position.m / np.linalg.norm(seen.position.m, axis=0)
    field = unit_vector_from_radec(field_ra_deg, field_dec_deg)
    separation = np.degrees(np.arccos(np.clip(np.einsum("ij,ji->i", field, moon_vec), -1, 1)))
    moon_geo = earth.at(t).observe(moon).position.m
    moon_to_sun = sun.at(t).position.m - (earth.at(t).position.m + moon_geo)
    cos_phase = np.einsum("ij,ij->j", -moon_geo, moon_to_sun) / (
        np.linalg.norm(moon_geo, axis=0) * np.linalg.norm(moon_to_sun, axis=0)
    )
    if sun_elevation_deg is None:
        sun_elevation_deg = site.at(t).observe(sun).apparent().altaz()[0].degrees
    return SkyConditions(
        target_zenith_deg=90.0 - np.asarray(field_elevation_deg, dtype=np.float64),
        sun_elevation_deg=np.asarray(sun_elevation_deg, dtype=np.float64),
        moon_zenith_deg=np.asarray(90.0 - moon_alt, dtype=np.float64),
        moon_phase_angle_deg=np.degrees(np.arccos(np.clip(cos_phase, -1.0, 1.0))),
        moon_separation_deg=np.asarray(separation, dtype=np.float64),
    )
