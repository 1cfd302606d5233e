"""Closed-form torque-free rigid-body motion (Jacobi elliptic functions).

Works in the principal frame with ascending moments ``I1 <= I2 <= I3``. The body rates
are Jacobi's solution of Euler's equations (Landau & Lifshitz, *Mechanics*, 3rd ed.,
§37; Markley & Crassidis 2014, ch. 3). The attitude is built
from the inertially fixed angular momentum L with z-x-z Euler angles (phi, theta,
psi) measured from L (Landau & Lifshitz §35 and §37): theta and psi follow
algebraically from the body direction of L, and the precession angle phi about L from
``dphi/dt = |L| (Ia wa^2 + Ib wb^2) / (Ia^2 wa^2 + Ib^2 wb^2)``, where (a, b) are the
two axes other than the "polar" axis the polhode circles. The rate is a smooth
periodic function of the elliptic argument, integrated exactly in a Fourier series
whose truncation is chosen so the precession angle is correct to ``atol_rad``.

Motion within 1e-9 of the separatrix (``1 - k^2 < 1e-9``) is not handled here
(:func:`analytic_principal` returns ``None``); the caller falls back to numerical
integration.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.special import ellipj, ellipk, ellipkinc

from speclight.attitude.quaternion import (
    FloatArray,
    quat_conjugate,
    quat_from_axis_angle,
    quat_from_matrix,
    quat_multiply,
)

#: |omega x (I omega)| below this times |omega| |I omega|: rotation about a principal
#: axis (the nutation it ignores is below 1e-13 rad).
STEADY_SIN_LIMIT = 1e-13
#: Closed form used only for 1 - k^2 above this; nearer the separatrix cephes' ellipj
#: switches to a first-order expansion in 1 - k^2 and the period grows without bound.
SEPARATRIX_LIMIT = 1e-9
#: Largest Fourier sample count tried for the precession rate before giving up.
MAX_SAMPLES = 2**16


def _zxz(phi: FloatArray, theta: FloatArray, psi: FloatArray) -> FloatArray:
    """Quaternion of Rz(phi) Rx(theta) Rz(psi) (body to L-frame)."""
    z = np.array([0.0, 0.0, 1.0])
    x = np.array([1.0, 0.0, 0.0])
    return quat_multiply(
        quat_multiply(quat_from_axis_angle(z, phi), quat_from_axis_angle(x, theta)),
        quat_from_axis_angle(z, psi),
    )


def _steady(t: FloatArray, q0: FloatArray, w0: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Uniform rotation about a fixed principal axis: q(t) = q0 ⊗ exp(w0 t / 2)."""
    rate = float(np.linalg.norm(w0))
    if rate == 0.0:
        return np.tile(q0, (t.size, 1)), np.zeros((t.size, 3))
    # Keep angles within one 4 pi cycle (the quaternion period) for accuracy.
    angle = np.mod(rate * t, 4.0 * np.pi)
    q = quat_multiply(q0, quat_from_axis_angle(w0 / rate, angle))
    return q, np.tile(w0, (t.size, 1))


def _sin_series(coeffs: FloatArray, x: FloatArray) -> FloatArray:
    """Sum_k coeffs[k-1] sin(k x) by Clenshaw's recurrence."""
    two_cos = 2.0 * np.cos(x)
    b1 = np.zeros_like(x)
    b2 = np.zeros_like(x)
    for c in coeffs[::-1]:
        b1, b2 = c + two_cos * b1 - b2, b1
    return b1 * np.sin(x)


def _precession_series(
    rate_fn: Callable[[FloatArray], FloatArray], half_period: float, scale: float, atol: float
) -> tuple[float, FloatArray] | None:
    """Mean and sine-series coefficients of the periodic antiderivative of a rate.

    ``rate_fn(u)`` is even and periodic with period ``2 * half_period`` in u. Returns
    (mean rate, c) such that the antiderivative is ``mean * u + sum c_k sin(k nu u)``,
    ``nu = pi / half_period``, truncated so that the dropped terms sum to less than
    ``atol * scale``.
    """
    nu = np.pi / half_period
    n = 64
    while n <= MAX_SAMPLES:
        u = 2.0 * half_period * np.arange(n) / n
        a = np.fft.rfft(rate_fn(u)).real / n
        k = np.arange(1, a.size)
        c = 2.0 * a[1:] / (k * nu)
        c[-1] *= 0.5  # Nyquist term is not doubled
        tail = np.abs(c[3 * c.size // 4 :])
        if np.max(tail, initial=0.0) < 1e-3 * atol * scale:
            # smallest kmax with sum_{k > kmax} |c_k| < atol * scale / 2
            tail_sum = np.cumsum(np.abs(c[::-1]))[::-1]
            keep = int(np.searchsorted(-tail_sum, -0.5 * atol * scale))
            return float(a[0]), c[:keep]
        n *= 2
    return None


def analytic_principal(
    t_s: FloatArray, moments: FloatArray, q0: FloatArray, w0: FloatArray, atol_rad: float
) -> tuple[FloatArray, FloatArray] | None:
    """Torque-free motion in closed form, in the principal frame.

    Parameters
    ----------
    t_s
        Times since the initial state [s], shape (N,).
    moments
        Principal moments [kg m^2], ascending, shape (3,).
    q0
        Principal-to-inertial unit quaternion at t = 0, shape (4,).
    w0
        Angular velocity at t = 0 in the principal frame [rad/s], shape (3,).
    atol_rad
        Bound on the Fourier truncation error of the precession angle about L [rad].

    Returns
    -------
    tuple of numpy.ndarray or None
        Quaternions (N, 4) and principal-frame angular velocities (N, 3) [rad/s], or
        ``None`` within 1e-9 of the separatrix (caller integrates numerically).
    """
    i1, i2, i3 = moments
    h0 = moments * w0
    cross = float(np.linalg.norm(np.cross(w0, h0)))
    if cross <= STEADY_SIN_LIMIT * float(np.linalg.norm(w0) * np.linalg.norm(h0)):
        return _steady(t_s, q0, w0)
    # Sign of L^2 - 2 E I2 decides which axis the polhode circles (Landau & Lifshitz §37).
    if i3 * (i3 - i2) * w0[2] ** 2 - i1 * (i2 - i1) * w0[0] ** 2 > 0.0:
        frame = np.eye(3)  # polar axis 3
    else:  # polar axis 1: right-handed relabelling (3, -2, 1)
        frame = np.array([[0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0]])
    i_w = np.abs(frame.T) @ moments
    w_w = frame.T @ w0
    j1, j2, j3 = i_w
    # Cancellation-free forms of 2 E I3 - L^2 and L^2 - 2 E I1 (working frame).
    d3 = j1 * (j3 - j1) * w_w[0] ** 2 + j2 * (j3 - j2) * w_w[1] ** 2
    d1 = j2 * (j2 - j1) * w_w[1] ** 2 + j3 * (j3 - j1) * w_w[2] ** 2
    m = float(np.clip((j2 - j1) * d3 / ((j3 - j2) * d1), 0.0, 1.0))
    if 1.0 - m < SEPARATRIX_LIMIT:
        return None
    amp1 = np.sqrt(d3 / (j1 * (j3 - j1)))
    amp2 = np.sqrt(d3 / (j2 * (j3 - j2)))
    amp3 = np.sqrt(d1 / (j3 * (j3 - j1))) * np.sign(w_w[2])
    # du/dt from Euler's second equation: j2 * amp2 * du/dt = (j3 - j1) * amp1 * amp3.
    rate = float(np.sign(j3 - j1) * np.sign(amp3) * np.sqrt((j3 - j2) * d1 / (j1 * j2 * j3)))
    u0 = float(ellipkinc(np.arctan2(w_w[1] / amp2, w_w[0] / amp1), m))
    quarter = float(ellipk(m))
    l_norm = float(np.linalg.norm(i_w * w_w))

    def omega_at(u: FloatArray) -> FloatArray:
        sn, cn, dn, _ = ellipj(u, m)
        return np.stack((amp1 * cn, amp2 * sn, amp3 * dn), axis=-1)

    def precession_rate(u: FloatArray) -> FloatArray:
        sn, cn, _, _ = ellipj(u, m)
        wa2, wb2 = (amp1 * cn) ** 2, (amp2 * sn) ** 2
        return l_norm * (j1 * wa2 + j2 * wb2) / (j1**2 * wa2 + j2**2 * wb2)

    series = _precession_series(precession_rate, quarter, abs(rate), atol_rad)
    if series is None:
        return None
    mean_rate, coeffs = series
    nu = np.pi / quarter

    u = rate * t_s + u0
    u_red = u - 4.0 * quarter * np.round(u / (4.0 * quarter))
    w_t = omega_at(u_red)
    w_start = omega_at(np.array([u0]))
    # Precession angle about L, zero at t = 0.
    p_start = _sin_series(coeffs, np.array([nu * u0]))[0]
    phi = mean_rate * t_s + (_sin_series(coeffs, nu * u_red) - p_start) / rate

    def euler_quat(w: FloatArray, phi_rad: FloatArray) -> FloatArray:
        l_body = i_w * w / l_norm
        theta = np.arctan2(np.hypot(l_body[:, 0], l_body[:, 1]), l_body[:, 2])
        psi = np.arctan2(l_body[:, 0], l_body[:, 1])
        return _zxz(phi_rad, theta, psi)

    q_frame = quat_from_matrix(frame)
    q0_w = quat_multiply(q0, q_frame)
    q_lframe = quat_multiply(q0_w, quat_conjugate(euler_quat(w_start, np.zeros(1))[0]))
    q_w = quat_multiply(q_lframe, euler_quat(w_t, phi))
    q = quat_multiply(q_w, quat_conjugate(q_frame))
    return q, w_t @ frame.T
