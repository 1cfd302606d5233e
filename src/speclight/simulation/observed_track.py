"""The target seen from the site, epoch by epoch: light time, observation geometry and the
sky position, for any orbit source (the pipeline's geometry stage and ``speclight passes``).

A trajectory is the orbit source read once, ``t -> (r_gcrs_m (N, 3), ok (N,))``
(:func:`speclight.orbit.orbit_sources.orbit_trajectory`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight import orbit
from speclight.constants import C_M_S
from speclight.orbit.observer import site_velocity_gcrs_m_s
from speclight.orbit.orbit_sources import Trajectory
from speclight.orbit.sky_position import SkyPosition, sky_position
from speclight.orbit.timescale import time_from_utc
from speclight.scenario.sections_geometry import Observer

#: Fixed-point iterations of the light-time equation; each gains a factor v/c ~ 3e-5, so two
#: leave < 1e-9 s (0.3 mm) for targets up to GEO.
LIGHT_TIME_ITERATIONS = 2
#: Half step of the central difference that gives the target's velocity [s]. Its error,
#: h^2/6 times the jerk (<= 0.01 m s-3 in LEO), is below 1 mm s-1; SGP4's and the tables'
#: position noise (< 1 um) adds < 1e-5 m s-1.
VELOCITY_HALF_STEP_S = 0.5


def standard_pressure_mbar(altitude_m: float) -> float:
    """Pressure of the ICAO standard atmosphere at ``altitude_m`` [mbar].

    ``p = 1013.25 (1 - 2.25577e-5 h)^5.25588`` (ICAO Doc 7488, troposphere).
    """
    return 1013.25 * (1.0 - 2.25577e-5 * altitude_m) ** 5.25588


@dataclass(frozen=True)
class Track:
    """The target where the received light left it, and the geometry seen from the site.

    Attributes
    ----------
    time_utc
        (N,) epochs of reception, UTC.
    t
        The same epochs as a skyfield ``Time``.
    r_target_gcrs_m
        (N, 3) target positions at emission [m] (NaN where ``ok`` is False).
    ok
        (N,) whether the orbit source gave a position.
    delay_s
        (N,) one-way light time [s] (0 with ``observer.light_time: false``).
    geometry
        Range, azimuth, elevation, Sun, shadow and phase angle
        (:class:`~speclight.orbit.observation.ObservationGeometry`).
    """

    time_utc: NDArray[np.datetime64]
    t: Any
    r_target_gcrs_m: NDArray[np.float64]
    ok: NDArray[np.bool_]
    delay_s: NDArray[np.float64]
    geometry: orbit.ObservationGeometry


def site_of(observer: Observer) -> orbit.Site:
    """The scenario's observer as an :class:`~speclight.orbit.observer.Site`."""
    return orbit.Site(observer.latitude_deg, observer.longitude_deg, observer.altitude_m)


def _at_emission(
    trajectory: Trajectory,
    time_utc: NDArray[np.datetime64],
    r_target: NDArray[np.float64],
    ok: NDArray[np.bool_],
    site: orbit.Site,
    t: object,
) -> tuple[NDArray[np.float64], NDArray[np.bool_], NDArray[np.float64]]:
    """Target positions at the time the received light left it (one-way light time).

    Solves ``|r(t - tau) - o(t)| = c tau`` by fixed-point iteration (Montenbruck & Gill,
    Satellite Orbits, 2000, sec. 6.2.1), the observer ``o`` at reception in GCRS (so the
    diurnal aberration of the moving site is included). Returns positions, the validity
    mask and ``tau`` [s].
    """
    r_site = orbit.site_position_gcrs_m(site, t)
    tau_s = np.zeros(time_utc.size)
    for _ in range(LIGHT_TIME_ITERATIONS):
        tau_s = np.nan_to_num(np.linalg.norm(r_target - r_site, axis=1) / C_M_S)
        emitted = time_utc - np.rint(tau_s * 1e9).astype("timedelta64[ns]")
        r_target, ok_emit = trajectory(time_from_utc(emitted))
        ok = ok & ok_emit
    tau_s = np.linalg.norm(r_target - r_site, axis=1) / C_M_S
    return r_target, ok, np.nan_to_num(tau_s)


def observed_track(
    observer: Observer, time_utc: NDArray[np.datetime64], trajectory: Trajectory
) -> Track:
    """Where the target is seen from the scenario's site at each epoch of ``time_utc``.

    Parameters
    ----------
    observer
        The scenario's ``observer`` section (site, light time, refraction).
    time_utc
        (N,) UTC epochs of reception, ``datetime64[ns]``.
    trajectory
        The orbit source, ``t -> (r_gcrs_m, ok)``.

    Returns
    -------
    Track
    """
    site = site_of(observer)
    t = time_from_utc(time_utc)
    r_target, ok = trajectory(t)
    delay_s = np.zeros(time_utc.size)
    if observer.light_time:
        r_target, ok, delay_s = _at_emission(trajectory, time_utc, r_target, ok, site, t)
    geo = orbit.observation_geometry(
        t,
        r_target,
        site,
        refraction=observer.refraction,
        temperature_C=observer.temperature_C,
        pressure_mbar=(
            observer.pressure_mbar
            if observer.pressure_mbar is not None
            else standard_pressure_mbar(observer.altitude_m)
        ),
    )
    return Track(time_utc, t, r_target, ok, delay_s, geo)


def target_velocity_gcrs_m_s(
    trajectory: Trajectory, emitted_utc: NDArray[np.datetime64], r_target: NDArray[np.float64]
) -> NDArray[np.float64]:
    """The target's velocity at ``emitted_utc`` [m s-1], (N, 3): a central difference of the
    trajectory over +-:data:`VELOCITY_HALF_STEP_S` (one-sided at the edge of a table)."""
    h = VELOCITY_HALF_STEP_S
    step = np.timedelta64(int(h * 1e9), "ns")
    r_plus, ok_plus = trajectory(time_from_utc(emitted_utc + step))
    r_minus, ok_minus = trajectory(time_from_utc(emitted_utc - step))
    v = (r_plus - r_minus) / (2.0 * h)
    forward = ok_plus & ~ok_minus
    backward = ok_minus & ~ok_plus
    v[forward] = (r_plus[forward] - r_target[forward]) / h
    v[backward] = (r_target[backward] - r_minus[backward]) / h
    return np.asarray(v, dtype=np.float64)


def track_sky_position(track: Track, trajectory: Trajectory, observer: Observer) -> SkyPosition:
    """Topocentric RA/Dec (astrometric ICRS and apparent of date) and angular rate of the
    target along ``track`` (:mod:`speclight.orbit.sky_position`)."""
    v_site = site_velocity_gcrs_m_s(site_of(observer), track.t)
    emitted = track.time_utc - np.rint(track.delay_s * 1e9).astype("timedelta64[ns]")
    v_target = target_velocity_gcrs_m_s(trajectory, emitted, track.r_target_gcrs_m)
    los = track.r_target_gcrs_m - track.geometry.r_site_gcrs_m
    if observer.light_time:  # the emission time moves with the range: d(t - tau)/dt
        unit = los / np.linalg.norm(los, axis=1, keepdims=True)
        range_rate = np.einsum("ij,ij->i", unit, v_target - v_site)
        v_target = v_target * (1.0 - range_rate / C_M_S)[:, None]
    return sky_position(track.t, los, v_target - v_site, track.delay_s, v_site)
