"""Geometry and attitude stage of the pipeline: scenario in, per-epoch arrays out."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from speclight import attitude as att
from speclight import orbit
from speclight import schema as v
from speclight.constants import C_M_S
from speclight.errors import InputError
from speclight.orbit.orbit_sources import Trajectory, no_position_message, orbit_trajectory
from speclight.orbit.staleness import warn_past_tables
from speclight.orbit.timescale import time_from_utc
from speclight.scenario import LoadedScenario
from speclight.scenario.sections_attitude import (
    InertialPointingAttitude,
    NadirAttitude,
    SunPointingAttitude,
    TableAttitude,
    TargetPointingAttitude,
)
from speclight.scenario.sections_geometry import (
    AxesOrientation,
    FixedAttitude,
    SpinAttitude,
    TimeGrid,
    TorqueFreeAttitude,
)
from speclight.simulate.attitude_stage import profile_attitude


@dataclass
class Geometry:
    """Per-epoch geometry of one scenario (SI units, GCRS unless named otherwise)."""

    time_utc: NDArray[np.datetime64]
    t_s: NDArray[np.float64]
    r_target_gcrs_m: NDArray[np.float64]
    orbit_ok: NDArray[np.bool_]
    range_m: NDArray[np.float64]
    azimuth_deg: NDArray[np.float64]
    elevation_deg: NDArray[np.float64]
    phase_angle_deg: NDArray[np.float64]
    sunlit_fraction: NDArray[np.float64]
    sun_distance_m: NDArray[np.float64]
    quaternion_body_to_gcrs: NDArray[np.float64]
    sun_direction_body: NDArray[np.float64]
    observer_direction_body: NDArray[np.float64]
    phase_vector_body: NDArray[np.float64]
    flags: NDArray[np.uint8]

    @property
    def observable(self) -> NDArray[np.bool_]:
        """Epochs whose target position and attitude are known and that are above the
        minimum elevation."""
        bad = v.FLAG_ORBIT_FAILED | v.FLAG_BELOW_MIN_ELEVATION | v.FLAG_ATTITUDE_UNDEFINED
        return (self.flags & bad) == 0


def standard_pressure_mbar(altitude_m: float) -> float:
    """Pressure of the ICAO standard atmosphere at ``altitude_m`` [mbar].

    ``p = 1013.25 (1 - 2.25577e-5 h)^5.25588`` (ICAO Doc 7488, troposphere).
    """
    return 1013.25 * (1.0 - 2.25577e-5 * altitude_m) ** 5.25588


def time_grid(grid: TimeGrid) -> NDArray[np.datetime64]:
    """UTC epochs from ``start`` to ``stop`` (included when on the grid) every ``step_s``."""
    start = np.datetime64(grid.start.replace(tzinfo=None), "ns")
    span_s = (grid.stop - grid.start).total_seconds()
    n = int(np.floor(span_s / grid.step_s + 1e-9)) + 1
    offsets_ns = np.rint(np.arange(n) * grid.step_s * 1e9).astype("timedelta64[ns]")
    return start + offsets_ns


def _trajectory(loaded: LoadedScenario, time_utc: NDArray[np.datetime64]) -> Trajectory:
    """Read the orbit source once (:func:`speclight.orbit.orbit_sources.orbit_trajectory`)."""
    values = loaded.scenario.orbit.model_dump()
    return orbit_trajectory(values, loaded.resolve, time_utc, loaded.source)


def _orientation(o: AxesOrientation) -> NDArray[np.float64]:
    if o.quaternion is not None:
        return np.asarray(o.quaternion, dtype=float)
    assert o.z_axis_ra_deg is not None and o.z_axis_dec_deg is not None
    assert o.x_axis_ra_deg is not None and o.x_axis_dec_deg is not None
    return att.frame_from_axes_radec(
        o.z_axis_ra_deg, o.z_axis_dec_deg, o.x_axis_ra_deg, o.x_axis_dec_deg
    )


def attitude_quaternions(
    cfg: FixedAttitude | SpinAttitude | TorqueFreeAttitude | None, t_s: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Body-to-GCRS quaternions (N, 4) for the scenario's attitude model (None, a
    geometry-only scenario without one: the identity, the body frame is the GCRS)."""
    if cfg is None:
        return np.broadcast_to([1.0, 0.0, 0.0, 0.0], (t_s.size, 4)).copy()
    if isinstance(cfg, FixedAttitude):
        return np.broadcast_to(_orientation(cfg), (t_s.size, 4)).copy()
    if isinstance(cfg, SpinAttitude):
        return att.spin_attitude(
            t_s,
            cfg.spin_axis_ra_deg,
            cfg.spin_axis_dec_deg,
            cfg.period_s,
            cfg.initial_phase_deg,
            spin_body_axis=cfg.spin_body_axis,
        )
    q, _ = att.torque_free_attitude(
        t_s,
        np.asarray(cfg.inertia_kg_m2, dtype=float),
        _orientation(cfg.initial_attitude),
        np.asarray(cfg.angular_velocity_body_rad_s, dtype=float),
        method=cfg.method,
        rtol=cfg.rtol,
        atol=cfg.atol,
    )
    return q


#: Attitude models whose quaternions need the orbit, the Sun or a table (attitude_stage.py).
PROFILES = (
    NadirAttitude,
    SunPointingAttitude,
    InertialPointingAttitude,
    TargetPointingAttitude,
    TableAttitude,
)

#: Fixed-point iterations of the light-time equation; each gains a factor v/c ~ 3e-5, so two
#: leave < 1e-9 s (0.3 mm) for targets up to GEO.
LIGHT_TIME_ITERATIONS = 2


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


def scenario_geometry(
    loaded: LoadedScenario,
    time_utc: NDArray[np.datetime64] | None = None,
    trajectory: Trajectory | None = None,
) -> Geometry:
    """Orbit, observer, Sun, shadow and attitude for every epoch of the scenario.

    ``time_utc``: UTC epochs to use instead of the scenario's time grid (e.g. the times of a
    measured light curve), ``datetime64``; the attitude's time origin stays ``time.start``.
    ``trajectory``: ``t -> (r_gcrs_m, ok)`` in place of the scenario's orbit source (the
    observed positions of ``orbit: {observed: true}``, built by ``speclight compare``).
    """
    sc = loaded.scenario
    start = np.datetime64(sc.time.start.replace(tzinfo=None), "ns")
    if time_utc is None:
        time_utc = time_grid(sc.time)
    else:
        time_utc = np.asarray(time_utc, dtype="datetime64[ns]").ravel()
        if time_utc.size == 0:
            raise InputError("no epochs given", source=loaded.source, field="time_utc")
    warn_past_tables(time_utc)
    t = time_from_utc(time_utc)
    t_s = (time_utc - start) / np.timedelta64(1, "s")
    site = orbit.Site(sc.observer.latitude_deg, sc.observer.longitude_deg, sc.observer.altitude_m)
    if trajectory is None:
        trajectory = _trajectory(loaded, time_utc)
    r_target, ok = trajectory(t)
    delay_s = np.zeros(t_s.size)
    if sc.observer.light_time:
        r_target, ok, delay_s = _at_emission(trajectory, time_utc, r_target, ok, site, t)
    geo = orbit.observation_geometry(
        t,
        r_target,
        site,
        refraction=sc.observer.refraction,
        temperature_C=sc.observer.temperature_C,
        pressure_mbar=(
            sc.observer.pressure_mbar
            if sc.observer.pressure_mbar is not None
            else standard_pressure_mbar(sc.observer.altitude_m)
        ),
    )
    # the attitude as it was when the light left the target
    if isinstance(sc.attitude, PROFILES):
        emitted = time_utc - np.rint(delay_s * 1e9).astype("timedelta64[ns]")
        q = profile_attitude(
            sc.attitude, loaded, trajectory, emitted, r_target, geo.sun_direction_gcrs
        )
    else:
        q = attitude_quaternions(sc.attitude, t_s - delay_s)
    sun_b, obs_b, phase_b = att.body_directions(
        q, geo.sun_direction_gcrs, geo.observer_direction_gcrs
    )
    flags = np.zeros(t_s.size, dtype=np.uint8)
    flags[~ok] |= v.FLAG_ORBIT_FAILED
    flags[ok & np.any(np.isnan(q), axis=1)] |= v.FLAG_ATTITUDE_UNDEFINED
    with np.errstate(invalid="ignore"):
        flags[~(geo.elevation_deg >= sc.observer.min_elevation_deg)] |= v.FLAG_BELOW_MIN_ELEVATION
        flags[geo.sunlit_fraction <= 0.0] |= v.FLAG_IN_SHADOW
        flags[(geo.sunlit_fraction > 0.0) & (geo.sunlit_fraction < 1.0)] |= v.FLAG_PENUMBRA
    if not np.any(ok):
        raise InputError(
            no_position_message(sc.orbit.model_dump()), source=loaded.source, field="time"
        )
    return Geometry(
        time_utc=time_utc,
        t_s=t_s,
        r_target_gcrs_m=r_target,
        orbit_ok=ok,
        range_m=geo.range_m,
        azimuth_deg=geo.azimuth_deg,
        elevation_deg=geo.elevation_deg,
        phase_angle_deg=geo.phase_angle_deg,
        sunlit_fraction=geo.sunlit_fraction,
        sun_distance_m=geo.sun_distance_m,
        quaternion_body_to_gcrs=q,
        sun_direction_body=sun_b,
        observer_direction_body=obs_b,
        phase_vector_body=phase_b,
        flags=flags,
    )


def pole_body(geo: Geometry) -> NDArray[np.float64]:
    """(N, 3) the celestial pole (GCRS z axis) in the body frame at each epoch."""
    from speclight.attitude.quaternion import quat_conjugate, quat_rotate

    q = quat_conjugate(geo.quaternion_body_to_gcrs)
    return np.asarray(quat_rotate(q, np.broadcast_to([0.0, 0.0, 1.0], (len(q), 3))))
