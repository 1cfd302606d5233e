"""Torque-free body rates and precession against closed forms derived here.

References
----------
* Landau & Lifshitz, *Mechanics*, 3rd ed. (1976), §37: body rates Ω1, Ω2, Ω3 of a
  triaxial top in Jacobi elliptic functions cn, sn, dn for L^2 > 2 E I2, and for
  L^2 < 2 E I2 "by interchanging the suffixes 1 and 3". Written out below from the
  book, not from speclight's code (which works in a relabelled frame and inverts the
  initial phase).
* Landau & Lifshitz §33 / Goldstein, Poole & Safko, *Classical Mechanics*, 3rd ed.,
  ch. 5 (torque-free symmetric body): a symmetric top's transverse rates turn about
  the symmetry axis at Ω = (I_s - I_t) ω_s / I_t in the body, and the symmetry axis
  precesses about the fixed angular momentum L at |L| / I_t in space.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.special import ellipj

from speclight.attitude import quat_to_matrix, torque_free_attitude

I_TRIAXIAL = np.array([1.0, 2.0, 3.0])  # kg m^2
Q0 = np.array([0.8, 0.2, -0.4, 0.4]) / np.linalg.norm([0.8, 0.2, -0.4, 0.4])
#: Body-rate error allowed for the numerical reference path [rad/s]: the global error
#: of DOP853 at rtol = 1e-12 grows about linearly with the angle turned and stays
#: below ~1e-11 rad/s over the ~300 rad spans here; tenfold margin.
IVP_RATE_TOL = 1e-10
#: Same for the closed-form path: exact up to float round-off in the elapsed phase
#: (~1e-16 per radian turned) and ellipj's ~1e-15 relative accuracy.
ANALYTIC_RATE_TOL = 1e-12
#: Direction-cosine tolerances for the space precession over ~200 rad of precession:
#: integration error (ivp, observed ~3e-11) and round-off 200 rad x 1e-16 (analytic).
IVP_ATTITUDE_TOL = 1e-9
ANALYTIC_ATTITUDE_TOL = 1e-12


def landau_rates(omega_start: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Landau & Lifshitz §37 rates for an initial state (w1, 0, w3), w1, w3 > 0 (tau = 0).

    Returns ω(t) (N, 3) for I = diag(1, 2, 3); picks the L^2 > 2 E I2 formulas or the
    ones with suffixes 1 and 3 interchanged.
    """
    i1, i2, i3 = I_TRIAXIAL
    two_e = float(np.sum(I_TRIAXIAL * omega_start**2))
    l2 = float(np.sum((I_TRIAXIAL * omega_start) ** 2))
    if l2 > two_e * i2:
        a1 = np.sqrt((two_e * i3 - l2) / (i1 * (i3 - i1)))
        a2 = np.sqrt((two_e * i3 - l2) / (i2 * (i3 - i2)))
        a3 = np.sqrt((l2 - two_e * i1) / (i3 * (i3 - i1)))
        rate = np.sqrt((i3 - i2) * (l2 - two_e * i1) / (i1 * i2 * i3))
        k2 = (i2 - i1) * (two_e * i3 - l2) / ((i3 - i2) * (l2 - two_e * i1))
        sn, cn, dn, _ = ellipj(rate * t, k2)
        return np.stack((a1 * cn, a2 * sn, a3 * dn), axis=-1)
    a3 = np.sqrt((two_e * i1 - l2) / (i3 * (i1 - i3)))
    a2 = np.sqrt((two_e * i1 - l2) / (i2 * (i1 - i2)))
    a1 = np.sqrt((l2 - two_e * i3) / (i1 * (i1 - i3)))
    rate = np.sqrt((i1 - i2) * (l2 - two_e * i3) / (i1 * i2 * i3))
    k2 = (i2 - i3) * (two_e * i1 - l2) / ((i1 - i2) * (l2 - two_e * i3))
    sn, cn, dn, _ = ellipj(rate * t, k2)
    return np.stack((a1 * dn, a2 * sn, a3 * cn), axis=-1)


# (w1, w3) at tau = 0: L^2 > 2 E I2, L^2 < 2 E I2, and L^2 > 2 E I2 with k^2 = 0.998
# near the separatrix w3 = w1 / sqrt(3).
CASES = {
    "L2>2EI2": (0.1, 0.3),
    "L2<2EI2": (0.3, 0.1),
    "near-separatrix": (0.3, 0.3 / np.sqrt(3.0) * 1.001),
}


@pytest.mark.parametrize("case", CASES)
def test_landau_reference_satisfies_euler_equations(case: str) -> None:
    # Guard on the reference itself: central-difference residual of I dω/dt + ω × Iω.
    w1, w3 = CASES[case]
    t = np.linspace(0.0, 60.0, 41)
    h = 1e-4
    w = landau_rates(np.array([w1, 0.0, w3]), t)
    dw = (
        landau_rates(np.array([w1, 0.0, w3]), t + h) - landau_rates(np.array([w1, 0.0, w3]), t - h)
    ) / (2 * h)
    residual = I_TRIAXIAL * dw + np.cross(w, I_TRIAXIAL * w)
    assert np.max(np.abs(residual)) < 1e-8  # O(h^2 ω^3) truncation of the difference


@pytest.mark.parametrize("method", ["analytic", "ivp"])
@pytest.mark.parametrize("case", CASES)
def test_triaxial_rates_match_jacobi_solution(case: str, method: str) -> None:
    w1, w3 = CASES[case]
    start = np.array([w1, 0.0, w3])
    # Start a quarter of the way into the motion (generic phase, all three rates != 0)
    # and follow ~40 polhode periods (periods 20-60 s here).
    shift = 7.3
    omega0 = landau_rates(start, np.array([shift]))[0]
    t = np.linspace(-30.0, 1000.0, 1500)
    _, omega = torque_free_attitude(t, I_TRIAXIAL, Q0, omega0, method=method)  # type: ignore[arg-type]
    tol = ANALYTIC_RATE_TOL if method == "analytic" else IVP_RATE_TOL
    np.testing.assert_allclose(omega, landau_rates(start, t + shift), rtol=0, atol=tol)


def _rotate_about(axis: np.ndarray, angle: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rodrigues' formula: v turned right-handedly by angle about unit axis."""
    c, s = np.cos(angle)[:, None], np.sin(angle)[:, None]
    return v * c + np.cross(axis, v) * s + axis * np.dot(axis, v) * (1 - c)


SYMMETRIC = {
    # moments, symmetry axis index, initial ω
    "oblate": (np.array([2.0, 2.0, 3.0]), 2, np.array([0.2, -0.1, 0.4])),
    "prolate": (np.array([1.0, 3.0, 3.0]), 0, np.array([0.5, 0.15, 0.1])),
}


@pytest.mark.parametrize("method", ["analytic", "ivp"])
@pytest.mark.parametrize("body", SYMMETRIC)
def test_symmetric_top_precession(body: str, method: str) -> None:
    moments, s, omega0 = SYMMETRIC[body]
    i_s, i_t = moments[s], moments[(s + 1) % 3]
    t = np.linspace(0.0, 300.0, 601)
    q, omega = torque_free_attitude(t, moments, Q0, omega0, method=method)  # type: ignore[arg-type]
    rate_tol = ANALYTIC_RATE_TOL if method == "analytic" else IVP_RATE_TOL
    att_tol = ANALYTIC_ATTITUDE_TOL if method == "analytic" else IVP_ATTITUDE_TOL

    # Body frame: ω_s constant, transverse ω turns about the symmetry axis at Ω.
    body_rate = (i_s - i_t) / i_t * omega0[s]
    e_s = np.eye(3)[s]
    transverse0 = omega0 - omega0[s] * e_s
    expected = _rotate_about(e_s, body_rate * t, transverse0) + omega0[s] * e_s
    np.testing.assert_allclose(omega, expected, rtol=0, atol=rate_tol)

    # Space: the symmetry axis precesses about L at |L| / I_t.
    r = quat_to_matrix(q)
    l_inertial = r[0] @ (moments * omega0)
    l_norm = float(np.linalg.norm(l_inertial))
    axis_gcrs = r[:, :, s]
    expected_axis = _rotate_about(l_inertial / l_norm, l_norm / i_t * t, axis_gcrs[0])
    np.testing.assert_allclose(axis_gcrs, expected_axis, rtol=0, atol=att_tol)
