"""Geometry and attitude stage of the pipeline: scenario in, per-epoch arrays out."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from speclight import attitude as att
from speclight import schema as v
from speclight.errors import InputError
from speclight.orbit.orbit_sources import (
    Trajectory,
    choices_text,
    no_position_message,
    orbit_trajectory,
)
from speclight.orbit.sky_position import SkyPosition
from speclight.orbit.staleness import warn_past_tables
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
from speclight.simulation.attitude_stage import profile_attitude
from speclight.simulation.observed_track import observed_track, track_sky_position


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
    flags: NDArray[np.uint16]
    #: The Sun's elevation at the site [deg] (geometric, of its centre).
    sun_elevation_deg: NDArray[np.float64]
    #: Where to point: topocentric RA/Dec and the angular rate on the sky.
    sky: SkyPosition

    @property
    def observable(self) -> NDArray[np.bool_]:
        """Epochs whose target position and attitude are known, above the minimum elevation,
        in a dark sky (the Sun below ``observer.max_sun_elevation_deg``)."""
        bad = (
            v.FLAG_ORBIT_FAILED
            | v.FLAG_BELOW_MIN_ELEVATION
            | v.FLAG_ATTITUDE_UNDEFINED
            | v.FLAG_DAYLIGHT
        )
        return (self.flags & bad) == 0


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
    t_s = (time_utc - start) / np.timedelta64(1, "s")
    if trajectory is None:
        trajectory = _trajectory(loaded, time_utc)
    track = observed_track(sc.observer, time_utc, trajectory)
    r_target, ok, delay_s, geo = track.r_target_gcrs_m, track.ok, track.delay_s, track.geometry
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
    flags = np.zeros(t_s.size, dtype=v.FLAG_DTYPE)
    flags[~ok] |= v.FLAG_ORBIT_FAILED
    flags[ok & np.any(np.isnan(q), axis=1)] |= v.FLAG_ATTITUDE_UNDEFINED
    with np.errstate(invalid="ignore"):
        flags[~(geo.elevation_deg >= sc.observer.min_elevation_deg)] |= v.FLAG_BELOW_MIN_ELEVATION
        flags[geo.sunlit_fraction <= 0.0] |= v.FLAG_IN_SHADOW
        flags[(geo.sunlit_fraction > 0.0) & (geo.sunlit_fraction < 1.0)] |= v.FLAG_PENUMBRA
    flags[geo.sun_elevation_deg > sc.observer.max_sun_elevation_deg] |= v.FLAG_DAYLIGHT
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
        sun_elevation_deg=geo.sun_elevation_deg,
        sky=track_sky_position(track, trajectory, sc.observer),
    )


def scenario_trajectory(loaded: LoadedScenario, time_utc: NDArray[np.datetime64]) -> Trajectory:
    """The scenario's orbit source read once, ``t -> (r_gcrs_m (N, 3), ok (N,))``, for a
    window spanning ``time_utc`` (``speclight passes``; ``observed: true`` has none)."""
    if loaded.scenario.orbit.observed:
        raise InputError(
            f"observed: true has no orbit of its own; give {choices_text(loadable=True)}",
            source=loaded.source,
            field="orbit.observed",
        )
    return _trajectory(loaded, time_utc)


def pole_body(geo: Geometry) -> NDArray[np.float64]:
    """(N, 3) the celestial pole (GCRS z axis) in the body frame at each epoch."""
    from speclight.attitude.quaternion import quat_conjugate, quat_rotate

    q = quat_conjugate(geo.quaternion_body_to_gcrs)
    return np.asarray(quat_rotate(q, np.broadcast_to([0.0, 0.0, 1.0], (len(q), 3))))
