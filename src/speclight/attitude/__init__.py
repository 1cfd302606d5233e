"""Attitude of the target: fixed, uniform spin, torque-free rigid body, operational profiles.

Conventions
-----------
* Quaternions are scalar-first ``(w, x, y, z)`` Hamilton quaternions of unit norm,
  stored as numpy arrays of shape (N, 4), one row per epoch.
* A quaternion ``q`` is the rotation from the BODY frame to the inertial frame (GCRS,
  treated as inertial): ``v_gcrs = R(q) @ v_body``; compositions follow the matrices,
  ``R(p ⊗ q) = R(p) @ R(q)``.
* Angular velocity is given in the body frame [rad/s]; kinematics
  ``dq/dt = ½ q ⊗ (0, ω_body)``.
* Right ascension and declination are in degrees in GCRS.
* Times are seconds since the scenario start, ``t_s`` (N,).

Models
------
:func:`fixed_attitude`
    Constant attitude from a quaternion or from z- and x-axis directions.
:func:`spin_attitude`
    Uniform rotation about an inertially fixed axis (body z).
:func:`torque_free_attitude`
    Free rigid body (Euler's equations): ``method="analytic"`` (default; Jacobi
    elliptic body rates, attitude from the fixed angular momentum, precession angle
    integrated to ``atol`` [rad]; falls back to ``"ivp"`` within 1e-9 of the
    separatrix) or ``method="ivp"`` (DOP853 at ``rtol``/``atol``, the reference).

:func:`nadir_attitude`
    Nadir pointing: body z to the geodetic (:func:`geodetic_up_itrs`) or geocentric nadir,
    x toward the velocity (LVLH) or yaw-steered to keep the Sun in the body x-z plane.
:func:`align_constrain`
    One body axis on a direction, a second as close as possible to another (Sun, inertial
    and ground-target pointing).
:func:`read_attitude_table`, :func:`slerp_table`
    Tabulated quaternions (CSV), slerped between rows, NaN outside the table.

:func:`body_directions` turns GCRS Sun and observer directions into the body-frame
unit vectors of the output dataset (``sun_direction_body``, ``observer_direction_body``,
``phase_vector_body``); the phase vector is the bisector ``normalize(sun + observer)``
and is NaN where the two are opposite (phase angle 180 deg) or an input row is bad.

Bad user input raises :class:`speclight.errors.InputError` naming the scenario field
(``attitude.period_s``, ``attitude.inertia_kg_m2``, ...); bad rows inside arrays (NaN,
zero vectors) come back as NaN rows instead.
"""

from speclight.attitude.body_frame import body_directions, to_body
from speclight.attitude.fixed import fixed_attitude
from speclight.attitude.inertia import PrincipalFrame, principal_frame
from speclight.attitude.nadir import geodetic_up_itrs, nadir_attitude
from speclight.attitude.pointing import align_constrain
from speclight.attitude.quaternion import (
    frame_from_axes,
    frame_from_axes_radec,
    quat_conjugate,
    quat_from_axis_angle,
    quat_from_matrix,
    quat_multiply,
    quat_normalize,
    quat_rotate,
    quat_to_axis_angle,
    quat_to_matrix,
    radec_from_unit_vector,
    unit_vector_from_radec,
)
from speclight.attitude.quaternion_table import (
    AttitudeTable,
    read_attitude_table,
    slerp_table,
)
from speclight.attitude.spin import spin_attitude
from speclight.attitude.torque_free import TorqueFreeMethod, torque_free_attitude

__all__ = [
    "AttitudeTable",
    "PrincipalFrame",
    "TorqueFreeMethod",
    "align_constrain",
    "body_directions",
    "fixed_attitude",
    "frame_from_axes",
    "frame_from_axes_radec",
    "geodetic_up_itrs",
    "nadir_attitude",
    "principal_frame",
    "quat_conjugate",
    "quat_from_axis_angle",
    "quat_from_matrix",
    "quat_multiply",
    "quat_normalize",
    "quat_rotate",
    "quat_to_axis_angle",
    "quat_to_matrix",
    "radec_from_unit_vector",
    "read_attitude_table",
    "slerp_table",
    "spin_attitude",
    "to_body",
    "torque_free_attitude",
    "unit_vector_from_radec",
]
