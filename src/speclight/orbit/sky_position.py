"""Where to point: the target's topocentric right ascension, declination and angular rate.

Two positions per epoch, as skyfield names them (Rhodes, skyfield, "Positions"):

* **astrometric, ICRS** (``ra_deg``, ``dec_deg``): the direction from the observer at
  reception to the target where the light left it, in the barycentric frame, without
  aberration: the position a plate solution against a star catalogue (Gaia, ICRS) measures.
  The pipeline solves the light time in the geocentric frame (GCRS); the barycentric
  direction adds the Earth's motion during the light time, ``u - V_earth tau`` (up to
  ``V_earth / c`` = 20.5"). skyfield: ``(earth + site).at(t).observe(earth + sat).radec()``.
* **apparent, of date** (``ra_apparent_deg``, ``dec_apparent_deg``): the astrometric vector
  aberrated by the observer's barycentric velocity (Earth plus the site's rotation; the
  relativistic formula of skyfield's ``add_aberration``, Kaplan et al. 1989, AJ 97, 1197,
  doi:10.1086/115064), rotated to the true equator and equinox of date
  (:func:`~speclight.orbit.frames.icrs_to_true_of_date`): the direction a mount points to.
  skyfield: ``...observe(...).apparent().radec(epoch='date')``. The gravitational deflection
  skyfield adds is below 0.001" for a target near the Earth and is left out.

The angular rate is that of the astrometric direction, ``|w_perp| / |u|`` with ``w`` the
rate of the line-of-sight vector and ``w_perp`` its part across the line of sight, split
into ``d(RA)/dt cos(Dec)`` (east) and ``d(Dec)/dt`` (north) [deg s-1]; a streak on a
sidereally tracking telescope is the rate times the exposure. The apparent direction's rate
differs from it by the change of aberration across the sky, < 1e-4 of the rate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from speclight.constants import C_M_S
from speclight.orbit.frames import (
    FAST_MIN_EPOCHS,
    TimeLike,
    as_time,
    hourly_interpolated,
    icrs_to_true_of_date,
)
from speclight.orbit.timescale import load_ephemeris

F64 = NDArray[np.float64]


@dataclass(frozen=True)
class SkyPosition:
    """Topocentric sky position and motion of the target, each of shape (N,).

    Attributes
    ----------
    ra_deg, dec_deg
        Astrometric right ascension and declination, ICRS [deg]; RA in [0, 360).
    ra_apparent_deg, dec_apparent_deg
        Apparent right ascension and declination, true equator and equinox of date [deg].
    angular_rate_deg_s
        Angular rate of the target across the sky [deg s-1].
    ra_cos_dec_rate_deg_s, dec_rate_deg_s
        Its components: d(RA)/dt cos(Dec) (positive east) and d(Dec)/dt (positive north)
        [deg s-1], ICRS.
    """

    ra_deg: F64
    dec_deg: F64
    ra_apparent_deg: F64
    dec_apparent_deg: F64
    angular_rate_deg_s: F64
    ra_cos_dec_rate_deg_s: F64
    dec_rate_deg_s: F64


def _earth_velocity_exact(t: object) -> F64:
    earth = load_ephemeris()["earth"]
    return np.asarray(earth.at(t).velocity.m_per_s, dtype=np.float64).T.reshape(-1, 3)


def earth_velocity_bcrs_m_s(t: TimeLike, exact: bool | None = None) -> F64:
    """Barycentric velocity of the geocentre (JPL DE421) [m s-1], shape (N, 3).

    Interpolated from a 1 h grid for N >= ``FAST_MIN_EPOCHS`` (its fastest term, the lunar
    month's 12 m s-1, leaves a 10-point interpolation error far below 1 um s-1).
    """
    t = as_time(t)
    if exact is None:
        exact = int(np.size(t.whole)) < FAST_MIN_EPOCHS
    return _earth_velocity_exact(t) if exact else hourly_interpolated(t, _earth_velocity_exact)


def _radec_deg(v: F64) -> tuple[F64, F64]:
    ra = np.degrees(np.arctan2(v[:, 1], v[:, 0])) % 360.0
    dec = np.degrees(np.arctan2(v[:, 2], np.hypot(v[:, 0], v[:, 1])))
    return ra, dec


def aberrate(direction: F64, observer_velocity_m_s: F64) -> F64:
    """Apply the aberration of light to unit directions (N, 3) for an observer moving at
    ``observer_velocity_m_s`` (N, 3): relativistic, as skyfield's ``add_aberration``
    (Kaplan et al. 1989, AJ 97, 1197, eq. 7; doi:10.1086/115064). Returns unit vectors."""
    beta = observer_velocity_m_s / C_M_S
    beta_mag = np.linalg.norm(beta, axis=1)
    gamma_inv = np.sqrt(1.0 - beta_mag**2)
    p = np.einsum("ij,ij->i", direction, beta)  # beta cos(angle)
    q = 1.0 + p / (1.0 + gamma_inv)
    out = (gamma_inv[:, None] * direction + q[:, None] * beta) / (1.0 + p)[:, None]
    return np.asarray(out / np.linalg.norm(out, axis=1, keepdims=True), dtype=np.float64)


def sky_position(
    t: TimeLike,
    line_of_sight_gcrs_m: F64,
    line_of_sight_rate_gcrs_m_s: F64,
    light_time_s: F64,
    site_velocity_gcrs_m_s: F64,
) -> SkyPosition:
    """Right ascension, declination and angular rate of a target seen from a site.

    Parameters
    ----------
    t
        Epochs of reception (N), skyfield ``Time`` or UTC ``datetime64``.
    line_of_sight_gcrs_m
        (N, 3) target (where the light left it) minus site (at reception), GCRS [m]; NaN
        rows give NaN.
    line_of_sight_rate_gcrs_m_s
        (N, 3) its rate of change [m s-1].
    light_time_s
        (N,) one-way light time [s]; 0 where the geometry has none (then the astrometric
        position is the geometric one at the epoch).
    site_velocity_gcrs_m_s
        (N, 3) the site's velocity, GCRS [m s-1]
        (:func:`~speclight.orbit.observer.site_velocity_gcrs_m_s`).

    Returns
    -------
    SkyPosition
    """
    t = as_time(t)
    u = np.asarray(line_of_sight_gcrs_m, dtype=np.float64)
    w = np.asarray(line_of_sight_rate_gcrs_m_s, dtype=np.float64)
    tau = np.asarray(light_time_s, dtype=np.float64)
    v_earth = earth_velocity_bcrs_m_s(t)
    # the barycentric light-time position: the Earth moved by V tau while the light travelled
    u_bcrs = u - v_earth * tau[:, None]
    dist = np.linalg.norm(u_bcrs, axis=1)
    unit = u_bcrs / dist[:, None]
    tau_rate = np.where(tau > 0.0, np.einsum("ij,ij->i", unit, w) / C_M_S, 0.0)
    w_bcrs = w - v_earth * tau_rate[:, None]
    ra, dec = _radec_deg(unit)
    apparent = aberrate(unit, v_earth + site_velocity_gcrs_m_s)
    of_date = np.einsum("nij,nj->ni", icrs_to_true_of_date(t), apparent)
    ra_app, dec_app = _radec_deg(of_date)
    across = w_bcrs - unit * np.einsum("ij,ij->i", unit, w_bcrs)[:, None]
    a, d = np.radians(ra), np.radians(dec)
    east = np.stack([-np.sin(a), np.cos(a), np.zeros_like(a)], axis=1)
    north = np.stack([-np.sin(d) * np.cos(a), -np.sin(d) * np.sin(a), np.cos(d)], axis=1)
    return SkyPosition(
        ra_deg=ra,
        dec_deg=dec,
        ra_apparent_deg=ra_app,
        dec_apparent_deg=dec_app,
        angular_rate_deg_s=np.degrees(np.linalg.norm(across, axis=1) / dist),
        ra_cos_dec_rate_deg_s=np.degrees(np.einsum("ij,ij->i", across, east) / dist),
        dec_rate_deg_s=np.degrees(np.einsum("ij,ij->i", across, north) / dist),
    )
