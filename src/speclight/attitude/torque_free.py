"""Torque-free rigid-body attitude from an inertia tensor and initial state.

Euler's equations ``I dω/dt = -ω × (I ω)`` (body frame) with the quaternion kinematics
``dq/dt = ½ q ⊗ (0, ω)`` (Landau & Lifshitz, *Mechanics*, 3rd ed., §36; Markley &
Crassidis 2014, ch. 3, doi:10.1007/978-1-4939-0802-8). Kinetic energy
and the inertial angular momentum ``R(q) I ω`` are conserved.

Two methods, tested against each other:

``"analytic"`` (default)
    Body rates in closed form from Jacobi elliptic functions, attitude from the fixed
    angular momentum and the precession angle about it, integrated exactly as a
    Fourier series truncated at ``atol`` [rad] (:mod:`.torque_free_analytic`). Its
    error does not grow with the number of epochs beyond float round-off in the
    elapsed phase (about 1e-16 times the number of radians turned). Within 1e-9 of
    the separatrix (``1 - k^2 < 1e-9``, a spin near the unstable intermediate axis)
    it falls back to ``"ivp"``.
``"ivp"``
    The reference: :func:`scipy.integrate.solve_ivp` with DOP853 in the principal
    frame at ``rtol``/``atol`` (applied to ω [rad/s] and q [1]), dense output at the
    requested epochs, quaternions renormalised. Slow for long spans (seconds per day
    of fast tumbling).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from speclight.attitude.fixed import validate_quaternion
from speclight.attitude.inertia import principal_frame
from speclight.attitude.quaternion import (
    FloatArray,
    quat_conjugate,
    quat_from_matrix,
    quat_multiply,
    quat_normalize,
)
from speclight.attitude.torque_free_analytic import analytic_principal
from speclight.errors import InputError, did_you_mean

TorqueFreeMethod = Literal["analytic", "ivp"]
METHODS: tuple[str, ...] = ("analytic", "ivp")


def _euler_rhs(moments: FloatArray) -> Callable[[float, FloatArray], list[float]]:
    i1, i2, i3 = (float(v) for v in moments)
    k1, k2, k3 = (i2 - i3) / i1, (i3 - i1) / i2, (i1 - i2) / i3

    def rhs(_t: float, y: FloatArray) -> list[float]:
        w1, w2, w3, qw, qx, qy, qz = y
        return [
            k1 * w2 * w3,
            k2 * w3 * w1,
            k3 * w1 * w2,
            -0.5 * (qx * w1 + qy * w2 + qz * w3),
            0.5 * (qw * w1 + qy * w3 - qz * w2),
            0.5 * (qw * w2 - qx * w3 + qz * w1),
            0.5 * (qw * w3 + qx * w2 - qy * w1),
        ]

    return rhs


def ivp_principal(
    t_s: FloatArray, moments: FloatArray, q0: FloatArray, w0: FloatArray, rtol: float, atol: float
) -> tuple[FloatArray, FloatArray]:
    """Integrate Euler's equations and quaternion kinematics in the principal frame.

    Integrates forward from 0 to ``max(t_s)`` and backward to ``min(t_s)`` as needed
    (DOP853, dense output). Returns quaternions (N, 4), renormalised, and angular
    velocities (N, 3) [rad/s] in the principal frame.
    """
    rhs = _euler_rhs(moments)
    y0 = np.concatenate((w0, q0))
    out = np.empty((t_s.size, 7))
    for sel, pick in ((t_s >= 0.0, np.max), (t_s < 0.0, np.min)):
        if not np.any(sel):
            continue
        end = float(pick(t_s[sel]))
        if end == 0.0:
            out[sel] = y0
            continue
        from scipy.integrate import solve_ivp  # 0.3 s of import: only for method='ivp'

        sol = solve_ivp(
            rhs, (0.0, end), y0, method="DOP853", rtol=rtol, atol=atol, dense_output=True
        )
        if not sol.success:  # pragma: no cover - DOP853 on this smooth system does not fail
            raise RuntimeError(f"torque-free integration failed: {sol.message}")
        out[sel] = sol.sol(t_s[sel]).T
    return quat_normalize(out[:, 3:]), out[:, :3]


def _check_method(method: str, rtol: float, atol: float) -> None:
    """A known method and finite tolerances > 0."""
    if method not in METHODS:
        raise InputError(
            f"unknown torque-free method {method!r}{did_you_mean(str(method), METHODS)} "
            f"(choices: {', '.join(METHODS)})",
            field="attitude.method",
        )
    for name, tol in (("rtol", rtol), ("atol", atol)):
        if not (np.isfinite(tol) and tol > 0.0):
            raise InputError(
                f"{name} = {tol!r} must be a finite number > 0", field=f"attitude.{name}"
            )


def torque_free_attitude(
    t_s: ArrayLike,
    inertia_kg_m2: ArrayLike,
    q0: ArrayLike,
    omega0_body_rad_s: ArrayLike,
    *,
    method: TorqueFreeMethod = "analytic",
    rtol: float = 1e-12,
    atol: float = 1e-13,
) -> tuple[FloatArray, FloatArray]:
    """Attitude and body rates of a rigid body rotating free of torques.

    Parameters
    ----------
    t_s
        Seconds since the initial state [s], shape (N,), any order, may be negative.
    inertia_kg_m2
        Principal moments (3,) along the body axes, or the symmetric positive-definite
        inertia tensor (3, 3) in the body frame [kg m^2]. Only ratios matter.
    q0
        Body-to-GCRS unit quaternion at ``t_s = 0``, scalar first (4,).
    omega0_body_rad_s
        Angular velocity at ``t_s = 0`` in the body frame [rad/s], shape (3,).
    method
        ``"analytic"`` (closed form, fast) or ``"ivp"`` (numerical reference); see the
        module docstring.
    rtol, atol
        Tolerances. ``"ivp"``: solve_ivp's relative and absolute tolerances on ω
        [rad/s] and q. ``"analytic"``: ``atol`` bounds the truncation error of the
        precession angle [rad]; ``rtol`` is unused (the rates are exact closed forms).

    Returns
    -------
    q : numpy.ndarray
        Body-to-GCRS unit quaternions, shape (N, 4).
    omega_body_rad_s : numpy.ndarray
        Angular velocity in the body frame [rad/s], shape (N, 3).

    Raises
    ------
    InputError
        For an invalid inertia tensor (field ``attitude.inertia_kg_m2``), quaternion,
        angular velocity, time array, tolerance or method.

    References
    ----------
    L. D. Landau and E. M. Lifshitz, *Mechanics*, 3rd ed. (1976), §§35-37.
    F. L. Markley and J. L. Crassidis, *Fundamentals of Spacecraft Attitude
    Determination and Control* (2014), ch. 3, doi:10.1007/978-1-4939-0802-8.
    """
    _check_method(method, rtol, atol)
    t = np.atleast_1d(np.asarray(t_s, dtype=np.float64))
    if t.ndim != 1 or not np.all(np.isfinite(t)):
        raise InputError(
            "t_s must be a 1-D array of finite seconds since the initial state", field="time"
        )
    frame = principal_frame(inertia_kg_m2)
    q_start = validate_quaternion(q0, "attitude.initial_attitude.quaternion")
    w_start = np.asarray(omega0_body_rad_s, dtype=np.float64)
    if w_start.shape != (3,) or not np.all(np.isfinite(w_start)):
        raise InputError(
            f"omega0_body_rad_s = {np.asarray(omega0_body_rad_s).tolist()} must be 3 finite "
            "numbers [rad/s] (body frame)",
            field="attitude.angular_velocity_body_rad_s",
        )
    # Principal frame: v_body = axes @ v_principal.
    q_axes = quat_from_matrix(frame.axes)
    q0_p = quat_multiply(q_start, q_axes)
    w0_p = frame.axes.T @ w_start
    result = None
    if method == "analytic":
        result = analytic_principal(t, frame.moments_kg_m2, q0_p, w0_p, atol)
    if result is None:
        result = ivp_principal(t, frame.moments_kg_m2, q0_p, w0_p, rtol, atol)
    q_p, w_p = result
    return quat_multiply(q_p, quat_conjugate(q_axes)), w_p @ frame.axes.T
