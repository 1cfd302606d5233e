"""The tumbling search's grid rates (issue 27): the light curves' periodogram against the
closed-form frequencies of torque-free motion, and the period range against the data span."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import ellipj, ellipk

from speclight.attitude import torque_free_attitude
from speclight.attitude.quaternion import quat_conjugate, quat_rotate
from speclight.estimate.shape.convex_model import facet_brightness
from speclight.estimate.shape.inversion_data import build_inversion_data
from speclight.estimate.shape.scattering import scattering_law
from speclight.estimate.shape.tumbling_search import (
    GROWTH,
    OVERSAMPLING,
    POINTS_PER_PARAMETER,
    grid_rates,
    light_curve_frequencies,
    local_draws,
    searched_period_range_h,
    window_schedule,
)

MOMENTS = np.array([0.45, 0.8, 1.0])  # principal moments, ascending
Q0 = np.array([0.9, 0.1, -0.3, 0.2]) / np.linalg.norm([0.9, 0.1, -0.3, 0.2])
#: A 3 x 2 x 1 box's faces (outward normals, areas), Lambertian.
NORMALS = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1.0]])
AREAS = np.array([2.0, 2.0, 3.0, 3.0, 6.0, 6.0])


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def landau_lifshitz_frequencies(moments, w0):
    """Frequencies [Hz] of torque-free motion, independently of speclight's propagation:
    the body rates' period ``T = 4 K(k) / lambda`` (Landau & Lifshitz, Mechanics, 3rd ed.,
    section 37, eqs. 37.10-37.11; the axes 1 and 3 swapped when ``M^2 < 2 E I_2``) and the
    mean precession rate about the momentum, ``dphi/dt = M (I1 w1^2 + I2 w2^2) / (I1^2 w1^2 +
    I2^2 w2^2)`` (ibid., 37.16), averaged over ``T`` by quadrature of scipy's Jacobi elliptic
    functions. A light curve seen from fixed directions is then quasi-periodic in both."""
    i1, i2, i3 = moments
    m2 = float(np.sum((moments * w0) ** 2))
    e2 = float(np.sum(moments * w0**2))  # 2 E
    if m2 < e2 * i2:
        i1, i3 = i3, i1
    k2 = (i2 - i1) * (e2 * i3 - m2) / ((i3 - i2) * (m2 - e2 * i1))
    lam = np.sqrt((i3 - i2) * (m2 - e2 * i1) / (i1 * i2 * i3))
    quarter = float(ellipk(k2))
    a1 = np.sqrt((e2 * i3 - m2) / (i1 * (i3 - i1)))
    a2 = np.sqrt((e2 * i3 - m2) / (i2 * (i3 - i2)))

    def phi_rate(tau: float) -> float:
        sn, cn, _, _ = ellipj(tau, k2)
        w1, w2 = a1 * cn, a2 * sn
        return float(np.sqrt(m2) * (i1 * w1**2 + i2 * w2**2) / (i1**2 * w1**2 + i2**2 * w2**2))

    mean_rate = quad(phi_rate, 0.0, 4 * quarter, limit=200)[0] / (4 * quarter)
    return lam / (4 * quarter), mean_rate / (2 * np.pi)


def _box_curve(t_s, moments, w0, curve=None):
    """The box's Lambert light curve under speclight's torque-free attitude, the Sun and the
    observer fixed (phase angle 70 deg), 1 % sigmas."""
    sun = np.tile(_unit(np.array([1.0, 0.2, 0.1])), (t_s.size, 1))
    obs = np.tile(_unit(np.array([0.3, 1.0, 0.3])), (t_s.size, 1))
    q, _ = torque_free_attitude(t_s, moments, Q0, w0)
    qc = quat_conjugate(q)
    chp = np.sqrt(0.5 * (1 + np.sum(sun * obs, axis=1)))
    law = scattering_law("lambert")
    y = facet_brightness(quat_rotate(qc, sun), quat_rotate(qc, obs), NORMALS, AREAS, law, chp)
    curve = np.zeros(t_s.size, dtype=int) if curve is None else curve
    calibrated = np.zeros(curve.max() + 1, dtype=bool)
    return build_inversion_data(
        2459000.5 + t_s / 86400.0, y, np.full(y.size, 0.01 * np.mean(y)), sun, obs, curve,
        calibrated, "box",
    )  # fmt: skip


def test_light_curve_frequencies_are_the_torque_free_motions():
    """On a long noiseless light curve of a tumbling box (both kinds of motion: about the
    axis of largest and of smallest moment), the two independent frequencies found are
    integer combinations ``|n f_psi + m f_phi|`` of Landau & Lifshitz's two (one periodogram
    step: the peak's resolution ``1 / T`` over the oversampling), and together they span
    both (the integer pairs are independent)."""
    t_s = np.arange(0.0, 20000.0, 5.0)
    step_hz = 1.0 / (OVERSAMPLING * np.ptp(t_s))
    for w0 in ([0.01, 0.03, 0.02], [0.03, 0.005, 0.01], [0.004, 0.006, 0.035]):
        f_psi, f_phi = landau_lifshitz_frequencies(MOMENTS, np.array(w0))
        found = light_curve_frequencies(_box_curve(t_s, MOMENTS, np.array(w0)), 0.02, 1.0)
        assert found.size == 2
        pairs = []
        for f in found:
            off, n, m = min(
                (abs(abs(n * f_psi + m * f_phi) - f), n, m)
                for n in range(-4, 5)
                for m in range(5)
                if (n, m) != (0, 0)
            )
            assert off < step_hz, (w0, f, n, m, off)
            pairs.append((n, m))
        assert pairs[0][0] * pairs[1][1] != pairs[0][1] * pairs[1][0], pairs


def test_principal_rotation_seeds_its_own_rate():
    """A box turning about its axis of largest moment, over two 10-min passes 90 min apart:
    its Lambert faces show alike every half turn, so the strongest frequency is twice the
    rotation's (closed form), and the grid's rates hold the true rate within a periodogram
    step's share of it (the 10-min passes' resolution over the oversampling)."""
    t_s = np.concatenate([np.arange(0, 600, 10.0), 5400 + np.arange(0, 600, 10.0)])
    w_rad_s = 0.035
    d = _box_curve(t_s, MOMENTS, np.array([0.0, 0.0, w_rad_s]), np.repeat([0, 1], 60))
    f = light_curve_frequencies(d, 0.03, 0.1)
    step_hz = 1.0 / (OVERSAMPLING * 590.0)
    assert abs(f[0] - 2 * w_rad_s / (2 * np.pi)) < step_hz
    rates = grid_rates(d, 0.03, 0.1)
    assert np.min(np.abs(rates - w_rad_s)) < np.pi * step_hz


def test_searched_periods_reach_the_longest_curves_span():
    """Periods searched: the given range, its end raised to the longest curve's span (here
    590 s, points every 10 s over 10 min) when that is longer, else kept."""
    t_s = np.concatenate([np.arange(0, 600, 10.0), 5400 + np.arange(0, 300, 10.0)])
    d = _box_curve(t_s, MOMENTS, np.array([0.0, 0.0, 0.035]), np.repeat([0, 1], [60, 30]))
    lo, hi = searched_period_range_h(d, 0.03, 0.1)
    jd_rounding_h = 2 * np.spacing(2459000.5) * 24.0  # two epochs' float64 rounding [h]
    assert lo == 0.03 and abs(hi - 590.0 / 3600.0) < jd_rounding_h
    assert searched_period_range_h(d, 0.03, 0.5) == (0.03, 0.5)


def test_refinement_jacobian_is_scipys_forward_differences(monkeypatch):
    """The fit's Jacobian (attitude columns on the state's own motion) against scipy's own
    2-point differences of the same residuals (scipy.optimize's ``approx_derivative``, the
    rule ``least_squares`` used before), at a state with ``u`` at its bound (a backward
    step): equal to float rounding, with 5 propagations beyond the state's own where
    scipy's takes 8."""
    from scipy.optimize._numdiff import approx_derivative

    from speclight.estimate.shape import tumbling
    from speclight.estimate.shape.tumbling_light import ConvexLight

    t_s = np.concatenate([np.arange(0, 600, 10.0), 5400 + np.arange(0, 600, 10.0)])
    d = _box_curve(t_s, MOMENTS, np.array([0.01, 0.03, 0.02]), np.repeat([0, 1], 60))
    light = ConvexLight(NORMALS, AREAS, scattering_law("lambert"))
    prob = tumbling._Problem(d, light, float(d.time_jd[0]))
    x = np.array([0.3, -0.2, 1.0, 0.012, 0.028, 0.019, 0.4, tumbling.MOMENT_BOUND])
    upper = np.full(8, np.inf)
    upper[6:8] = tumbling.MOMENT_BOUND
    lower = -upper
    reference = approx_derivative(prob.residuals, x, method="2-point", bounds=(lower, upper))
    calls = []
    real = tumbling.torque_free_attitude
    monkeypatch.setattr(
        tumbling, "torque_free_attitude", lambda *a, **k: calls.append(1) or real(*a, **k)
    )
    prob = tumbling._Problem(d, light, float(d.time_jd[0]))
    jac = prob.jacobian(x, lower, upper)
    n_propagations = len(calls)
    # a hundred roundings of a residual (the propagation's, the light's) over the step
    rounding = 100 * np.finfo(float).eps / np.sqrt(np.finfo(float).eps)
    assert np.max(np.abs(jac - reference)) <= rounding * np.max(np.abs(prob.residuals(x)))
    # the state's own motion (kept from its residuals inside least_squares), then one per
    # rate and moment parameter
    assert n_propagations == 6


def test_first_windows_turns_and_points():
    """The continuation's first windows: 1.5 turns of the fastest period, and in the second
    continuation widened to hold 3 points per parameter (8 or 9) where that is fewer; each
    next window twice as wide, the last reaching every point. A pass of 60 points every
    10 s with ``t0`` at its start: 1.5 turns of 108 s (81 s) hold 9 points, so the second
    continuation's first window is widened to the 24th point
    (230 s); with ``t0`` in its middle to the 24th nearest (+-120 s); a slow fastest period
    keeps its 1.5 turns."""
    t_s = np.arange(0, 600, 10.0)
    assert POINTS_PER_PARAMETER == (0, 3)
    assert window_schedule(t_s, 108.0) == pytest.approx([81.0, 162.0, 324.0, 590.0])  # 9-60 pts
    halves = window_schedule(t_s, 108.0, 3 * 8)
    assert halves == pytest.approx([230.0, GROWTH * 230.0, 590.0])
    assert np.sum(np.abs(t_s) <= halves[0]) == 24
    centred = t_s - 295.0
    assert np.sum(np.abs(centred) <= window_schedule(centred, 108.0, 24)[0]) >= 24
    assert np.sum(np.abs(t_s) <= window_schedule(t_s, 108.0, 27)[0]) == 27
    assert window_schedule(t_s, 400.0, 24)[0] == pytest.approx(300.0)  # 0.75 x 400 s: 31 points


def test_local_draws_spread_like_refits_over_noise():
    """Draws around a least-squares solution spread as the solution itself does over
    noise draws: a linear model ``y = A x + e`` (e ~ N(0, 0.3^2)) solved for 2,000 noise
    draws gives the estimator's covariance by Monte Carlo (no formula of the code's);
    4,000 draws of :func:`local_draws` (spread 1) around one solution have the same
    variances and correlations. Tolerances: 4 standard errors of a variance estimated
    from 2,000 and 4,000 samples and of the residual variance on 297 degrees of
    freedom (relative ``sqrt(2 / n)`` each), and 0.1 on correlations (0.02 s.e.)."""
    rng = np.random.default_rng(11)
    a = rng.normal(size=(300, 3)) * np.array([1.0, 0.2, 3.0])
    a[:, 1] += 0.8 * a[:, 0]  # correlated columns
    x_true = np.array([1.0, -2.0, 0.5])
    fits = np.array(
        [np.linalg.lstsq(a, a @ x_true + 0.3 * rng.normal(size=300), rcond=None)[0]
         for _ in range(2000)]
    )  # fmt: skip
    y = a @ x_true + 0.3 * rng.normal(size=300)
    x_hat = np.linalg.lstsq(a, y, rcond=None)[0]
    draws = local_draws(x_hat, a, y - a @ x_hat, rng, n=4000, spread=1.0)
    assert draws.shape == (4000, 3)
    var_fit, var_draw = np.var(fits, axis=0), np.var(draws, axis=0)
    rel_se = np.sqrt(2 / 2000 + 2 / 4000 + 2 / 297)
    assert np.all(np.abs(var_draw / var_fit - 1.0) < 4 * rel_se)
    assert np.allclose(np.corrcoef(draws.T), np.corrcoef(fits.T), atol=0.1)
    assert np.allclose(np.mean(draws, axis=0), x_hat, atol=4 * np.sqrt(var_fit / 4000))
    wide = local_draws(x_hat, a, y - a @ x_hat, rng, n=4000, spread=3.0)
    assert np.all(np.abs(np.var(wide, axis=0) / (9 * var_fit) - 1.0) < 4 * rel_se)
