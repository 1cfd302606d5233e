"""The operational attitude profiles in the pipeline: the per-epoch vectors they need.

The profiles (:mod:`speclight.attitude.nadir`, :mod:`~speclight.attitude.pointing`,
:mod:`~speclight.attitude.quaternion_table`) take plain GCRS vectors; this module builds
them from what the geometry stage has, at the time the received light left the target
(``emitted``): the target's position (light-time corrected), its velocity (central
difference of the trajectory over ``VELOCITY_STEP``), the Earth's orientation (for the
geodetic nadir and a ground site), and the target-to-Sun direction of the observation
geometry (the Sun's apparent position at reception; the ~20 ms between emission and
reception turn the Sun's direction by < 1e-7 rad).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight import orbit
from speclight.attitude.nadir import geodetic_up_itrs, nadir_attitude
from speclight.attitude.pointing import align_constrain
from speclight.attitude.quaternion import unit_vector_from_radec
from speclight.attitude.quaternion_table import read_attitude_table, slerp_table
from speclight.orbit.timescale import time_from_utc
from speclight.scenario import LoadedScenario
from speclight.scenario.sections_attitude import (
    InertialPointingAttitude,
    NadirAttitude,
    ProfileAttitude,
    SunPointingAttitude,
    TableAttitude,
    TargetPointingAttitude,
)

#: Half the central-difference step of the velocity. SGP4 and the 10-point Lagrange tables
#: are smooth over it: the truncation error h^2/6 |d3r/dt3| ~ h^2 n^3 r / 6 is < 5e-4 m/s
#: in LEO (< 1e-7 rad of the direction), and the positions' round-off (< 1e-5 m) adds
#: < 1e-5 m/s.
VELOCITY_STEP = np.timedelta64(500_000_000, "ns")

Trajectory = Callable[[Any], tuple[NDArray[np.float64], NDArray[np.bool_]]]


class _Vectors:
    """The per-epoch GCRS vectors of one run, each computed once when first asked for."""

    def __init__(
        self,
        trajectory: Trajectory,
        emitted_utc: NDArray[np.datetime64],
        r_target_gcrs_m: NDArray[np.float64],
        sun_dir_gcrs: NDArray[np.float64],
    ) -> None:
        self.trajectory = trajectory
        self.emitted = emitted_utc
        self.r = r_target_gcrs_m
        self.sun = sun_dir_gcrs
        self._t: Any = None
        self._v: NDArray[np.float64] | None = None

    @property
    def t(self) -> Any:
        if self._t is None:
            self._t = time_from_utc(self.emitted)
        return self._t

    def velocity(self) -> NDArray[np.float64]:
        """GCRS velocity [m/s]: central difference, one-sided where a neighbour is missing."""
        if self._v is None:
            h_s = VELOCITY_STEP / np.timedelta64(1, "s")
            after, _ = self.trajectory(time_from_utc(self.emitted + VELOCITY_STEP))
            before, _ = self.trajectory(time_from_utc(self.emitted - VELOCITY_STEP))
            v = (after - before) / (2.0 * h_s)
            v = np.where(np.isnan(v), (after - self.r) / h_s, v)
            self._v = np.where(np.isnan(v), (self.r - before) / h_s, v)
        return self._v

    def geodetic_nadir(self) -> NDArray[np.float64]:
        """Minus the WGS84 ellipsoid normal through the target, GCRS."""
        eo = orbit.earth_orientation(self.t)
        return -eo.itrs_to_gcrs(geodetic_up_itrs(eo.gcrs_to_itrs_vec(self.r)))

    def reference(self, name: str, ra_deg: float | None, dec_deg: float | None) -> Any:
        """A constraint direction by name (see ``sections_attitude.Constraint``)."""
        if name == "orbit_normal":
            return np.cross(self.r, self.velocity())
        if name == "velocity":
            return self.velocity()
        if name == "nadir":
            return self.geodetic_nadir()
        if name == "geocentre":
            return -self.r
        if name == "sun":
            return self.sun
        assert ra_deg is not None and dec_deg is not None
        return unit_vector_from_radec(ra_deg, dec_deg)


def profile_attitude(
    cfg: ProfileAttitude,
    loaded: LoadedScenario,
    trajectory: Trajectory,
    emitted_utc: NDArray[np.datetime64],
    r_target_gcrs_m: NDArray[np.float64],
    sun_dir_gcrs: NDArray[np.float64],
) -> NDArray[np.float64]:
    """Body-to-GCRS quaternions (N, 4) of an operational profile; NaN where undefined.

    Parameters
    ----------
    cfg
        The scenario's attitude section (a profile model).
    loaded
        The scenario (to resolve a table's path).
    trajectory
        ``t -> (r_gcrs_m, ok)`` of the orbit source.
    emitted_utc
        (N,) UTC epochs at which the received light left the target.
    r_target_gcrs_m
        (N, 3) target positions at those epochs [m].
    sun_dir_gcrs
        (N, 3) target-to-Sun directions.
    """
    vec = _Vectors(trajectory, emitted_utc, r_target_gcrs_m, sun_dir_gcrs)
    if isinstance(cfg, TableAttitude):
        table = read_attitude_table(loaded.resolve(cfg.file), field="attitude.file")
        q, _ = slerp_table(table.times_utc, table.q_body_to_gcrs, emitted_utc)
        return q
    if isinstance(cfg, NadirAttitude):
        nadir = vec.geodetic_nadir() if cfg.nadir_type == "geodetic" else -r_target_gcrs_m
        return nadir_attitude(
            nadir,
            vec.velocity(),
            sun_dir_gcrs,
            yaw_steering=cfg.yaw_steering,
            sun_side=cfg.yaw_sun_side,
        )
    if isinstance(cfg, SunPointingAttitude):
        primary: Any = sun_dir_gcrs
    elif isinstance(cfg, InertialPointingAttitude):
        primary = unit_vector_from_radec(cfg.target_ra_deg, cfg.target_dec_deg)
    else:
        assert isinstance(cfg, TargetPointingAttitude)
        site = orbit.Site(cfg.site_latitude_deg, cfg.site_longitude_deg, cfg.site_altitude_m)
        primary = orbit.site_position_gcrs_m(site, vec.t) - r_target_gcrs_m
    secondary = vec.reference(cfg.constraint, cfg.constraint_ra_deg, cfg.constraint_dec_deg)
    n = r_target_gcrs_m.shape[0]
    return align_constrain(
        cfg.pointing_axis_body,
        np.broadcast_to(primary, (n, 3)),
        cfg.constraint_axis_body,
        np.broadcast_to(secondary, (n, 3)),
        field="attitude",
    )
