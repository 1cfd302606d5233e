"""The solver pieces of shape inversion: LM, the DAMIT rotation, solution bookkeeping, the
scan shared among processes, the bootstrap and the ambiguity bound."""

from __future__ import annotations

import numpy as np
import pytest
from synthetic import apparitions, lambert_mesh_brightness, to_body

from conftest import ellipsoid_mesh
from speclight.estimate.shape import period_scan
from speclight.estimate.shape.convex_fit import ConvexSolution, fit_convex
from speclight.estimate.shape.convex_model import N_ROTATION, ConvexModel, ecliptic_to_body
from speclight.estimate.shape.egi import facet_normals
from speclight.estimate.shape.inversion_data import build_inversion_data
from speclight.estimate.shape.lm_solver import LmResult, levenberg_marquardt
from speclight.estimate.shape.pole_search import distinct_solutions, nearest_solution
from speclight.estimate.shape.scattering import scattering_law
from speclight.estimate.shape.uncertainty import (
    Covariance,
    ambiguity_bound,
    bootstrap,
    covariance,
    mirror_ambiguous,
)


def test_lm_reaches_the_rosenbrock_minimum():
    """Rosenbrock's valley as residuals (10 (y - x^2), 1 - x) from the classic start
    (-1.2, 1): the minimum is (1, 1) with cost 0 (Rosenbrock 1960, Comput. J. 3, 175); the
    Jacobian is asked for only at the steps taken, not at failed trials."""
    asked = []

    def fun(x):
        r = np.array([10.0 * (x[1] - x[0] ** 2), 1.0 - x[0]])

        def jac():
            asked.append(x.copy())
            return np.array([[-20.0 * x[0], 10.0], [-1.0, 0.0]])

        return r, jac

    out = levenberg_marquardt(fun, np.array([-1.2, 1.0]), np.ones(2, bool), max_iterations=200)
    assert out.converged
    assert np.allclose(out.x, [1.0, 1.0], atol=1e-4)
    assert out.cost < 1e-8
    assert len(asked) == out.iterations + 1  # the start and every step taken
    assert out.evaluations >= out.iterations


def test_lm_holds_fixed_parameters():
    """A parameter not free stays where it started; the free one reaches its optimum given
    it (residuals x0 - 2, x1 - 3, x0 x1 - 5 with x0 held at 1: x1 minimises (x1 - 3)^2 +
    (x1 - 5)^2, so x1 = 4)."""

    def fun(x):
        r = np.array([x[0] - 2.0, x[1] - 3.0, x[0] * x[1] - 5.0])
        return r, lambda: np.array([[1.0, 0.0], [0.0, 1.0], [x[1], x[0]]])

    out = levenberg_marquardt(fun, np.array([1.0, 0.0]), np.array([False, True]))
    assert out.x[0] == 1.0
    assert out.x[1] == pytest.approx(4.0, abs=1e-4)


def test_lm_rejects_an_overflowing_trial_step_quietly():
    # A trial step into a region whose residuals are finite but huge (1e200: their sum of
    # squares overflows to inf) is rejected like any worse step (more damping), with no
    # RuntimeWarning reaching the user (it printed "overflow encountered in matmul").
    import warnings

    calls = {"wild": 0}

    def fun(x):
        if abs(x[0] - 2.0) > 1.0:  # far from the minimum at 2: a wild region
            calls["wild"] += 1
            return np.array([1e200, 1e200]), lambda: np.array([[1.0], [1.0]])
        return np.array([x[0] - 2.0, 0.0]), lambda: np.array([[1.0], [0.0]])

    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        # a Jacobian 1000x too small makes the first, weakly damped step overshoot from 1.5
        # into the wild region; damping then brings the steps back
        out = levenberg_marquardt(
            lambda x: (fun(x)[0], lambda: 1e-3 * fun(x)[1]()), np.array([1.5]), np.ones(1, bool)
        )
    assert calls["wild"] >= 1
    assert out.x[0] == pytest.approx(2.0, abs=1e-3)


def _passive(axis: int, angle: float) -> np.ndarray:
    """The matrix turning coordinates by ``angle`` about ``axis`` (a frame rotation)."""
    c, s = np.cos(angle), np.sin(angle)
    i, j = [k for k in range(3) if k != axis]
    m = np.eye(3)
    m[i, i] = m[j, j] = c
    m[i, j], m[j, i] = (s, -s) if axis != 1 else (-s, s)
    return m


def test_ecliptic_to_body_is_damits_rotation():
    """DAMIT's frame (convexinv, Kaasalainen, Torppa & Muinonen 2001, Icarus 153, 37, sec.
    2.1): ecliptic coordinates turned about z by lambda, about the new y by the pole's
    colatitude 90 - beta, then about the pole by phi = omega (t - t0); the body turns
    forward (phi grows with time) and the pole is the body's +z."""
    lam, bet, period_h = np.deg2rad(253.0), np.deg2rad(-15.0), 5.76198
    t = np.array([0.0, 0.37, 3.1])
    phi = 2 * np.pi * 24.0 * t / period_h
    expected = [_passive(2, f) @ _passive(1, np.pi / 2 - bet) @ _passive(2, lam) for f in phi]
    got = ecliptic_to_body(lam, bet, period_h, t)
    assert np.allclose(got, expected, atol=1e-12)
    pole = np.array([np.cos(bet) * np.cos(lam), np.cos(bet) * np.sin(lam), np.sin(bet)])
    assert np.allclose(got @ pole, [0.0, 0.0, 1.0], atol=1e-12)
    # prograde about the pole: a fixed ecliptic direction turns by -phi in the body frame
    v = np.cross([0.0, 0.0, 1.0], pole)
    body = got @ (v / np.linalg.norm(v))
    turn = np.arctan2(body[:, 1], body[:, 0]) - np.arctan2(body[0, 1], body[0, 0])
    assert np.allclose(np.angle(np.exp(1j * (turn + phi))), 0.0, atol=1e-9)


def _solution(lam: float, bet: float, chi2: float) -> ConvexSolution:
    theta = np.array([np.deg2rad(lam), np.deg2rad(bet), 5.0, 0.0])
    lm = LmResult(theta, chi2, np.zeros(1), np.zeros((1, 4)), 1, True)
    return ConvexSolution(theta, chi2, lm)


def test_distinct_solutions_and_the_mirror():
    """Fits from several starts: two ended near (70, -15), two near (253, -17) (the pair of
    poles of DAMIT's example data, convexinv: 253.3, -16.9 and 70.2, -17.1). Kept: the
    lowest of each; the mirror of the best, (250, -15), is the one near (253, -17)."""
    sols = [
        _solution(70.5, -14.8, 3253.0),
        _solution(253.2, -17.2, 3239.0),
        _solution(70.5, -15.4, 3193.0),
        _solution(252.7, -14.7, 3410.0),
    ]
    kept = distinct_solutions(sols)
    assert [(s.lambda_deg, s.chi2) for s in kept] == [
        (pytest.approx(70.5), 3193.0),
        (pytest.approx(253.2), 3239.0),
    ]
    best = kept[0]
    mirror = nearest_solution(kept[1:], best.lambda_deg + 180.0, best.beta_deg)
    assert mirror is kept[1]
    assert nearest_solution(kept[1:], best.lambda_deg, -best.beta_deg + 60.0) is None


def test_scan_in_processes_is_the_scan(monkeypatch):
    """The trial periods shared among two processes give the same chi-square curve and best
    fit as one process (each trial independent of the others)."""
    rng = np.random.default_rng(5)
    t, sun, obs, curve = apparitions(rng, n_apparitions=3, step_h=0.5)
    vertices, faces = ellipsoid_mesh()
    sb, ob = (to_body(x, 30.0, 40.0, 6.0, t, np.floor(t[0])) for x in (sun, obs))
    y = lambert_mesh_brightness(vertices, faces, sb, ob)
    d = build_inversion_data(t, y, 0.01 * y, sun, obs, curve, np.zeros(curve.max() + 1, bool), "x")
    model = ConvexModel(d, facet_normals(1), scattering_law("lambert"), float(np.floor(t[0])))
    grid = period_scan.period_grid_h(5.99, 6.01, d.baseline_d)
    monkeypatch.setattr(period_scan, "PARALLEL_TRIALS", 2)
    kw = {"n_start_poles": 2, "max_iterations": 10}
    one = period_scan.scan_periods(model, grid, workers=1, **kw)
    two = period_scan.scan_periods(model, grid, workers=2, **kw)
    assert grid.size >= 4
    assert np.array_equal(one.chi2, two.chi2)
    assert np.array_equal(one.fitted_period_h, two.fitted_period_h, equal_nan=True)
    assert np.array_equal(one.best.theta, two.best.theta)


def test_bootstrap_spread_is_the_covariance():
    """Points drawn from a 12-facet model with 1 % Gaussian noise (so the noise, not model
    error, makes the residuals): the bootstrap's spread of pole and period and the Laplace
    covariance ``s^2 (J^T J)^-1`` are two routes to one quantity and agree (Efron &
    Tibshirani 1993, sec. 6.5, for least squares). 40 draws give a standard deviation to
    1 / sqrt(2 * 39) = 11 % (1 sigma); allowed: a factor 1.5 (the bootstrap refits a
    nonlinear model in 20 steps). Each draw also gives the facet areas of its refit:
    positive, their shares of the total spread as the covariance of the shares says (the
    median facet), about the solution's."""
    rng = np.random.default_rng(5)
    t, sun, obs, curve = apparitions(rng, n_apparitions=4, step_h=0.5)
    vertices, faces = ellipsoid_mesh()
    sb, ob = (to_body(x, 30.0, 40.0, 6.0, t, np.floor(t[0])) for x in (sun, obs))
    relative = np.zeros(curve.max() + 1, bool)
    law, t0 = scattering_law("lambert"), float(np.floor(t[0]))
    y = lambert_mesh_brightness(vertices, faces, sb, ob)
    start = ConvexModel(
        build_inversion_data(t, y, None, sun, obs, curve, relative, "x"), facet_normals(1), law, t0
    )
    truth = fit_convex(start, 30.0, 40.0, 6.0)
    clean = start.fitted(truth.theta)
    sigma = 0.01 * clean
    noisy = clean + sigma * np.random.default_rng(1).normal(size=clean.size)
    d = build_inversion_data(t, noisy, sigma, sun, obs, curve, relative, "x")
    model = ConvexModel(d, facet_normals(1), law, t0)
    sol = fit_convex(
        model, truth.lambda_deg, truth.beta_deg, truth.period_h, log_areas=truth.theta[N_ROTATION:]
    )
    cov = covariance(model, sol)
    samples, areas = bootstrap(model, sol, 40, 1)
    ratio = samples.std(axis=0, ddof=1) / [cov.lambda_deg, cov.beta_deg, cov.period_h]
    assert np.all((ratio > 1 / 1.5) & (ratio < 1.5)), ratio
    assert areas.shape == (40, 12) and np.all(areas > 0)
    fractions = areas / areas.sum(axis=1, keepdims=True)
    # relative curves: the areas' shares (the scale is not measured), median over facets
    share = np.median(np.log(fractions).std(axis=0, ddof=1) / cov.log_area)
    assert 1 / 1.5 < share < 1.5, share
    mean, spread = fractions.mean(axis=0), fractions.std(axis=0, ddof=1)
    # the mean of 40 draws is within 4 standard errors of the solution's fractions
    assert np.all(np.abs(mean - sol.areas / sol.areas.sum()) <= 4 * spread / np.sqrt(40) + 1e-12)


def test_a_pole_pair_within_the_chi_square_spread_is_ambiguous():
    """DAMIT's example light curves (1541 points; convexinv and this code find the poles
    (70, -15) and (253, -17), the published one (253, -15) the second, Kaasalainen, Torppa &
    Piironen 2002, Icarus 159, 369): chi-square 3189 at the first; the second refitted to
    3201 or 3239 from different starts; nu = 1440 residual degrees of freedom. A rise of 50
    is more than the 99 % point of chi-square(2) times s^2 (9.21 * 2.21 = 20)
    but within half the chi-square's own spread, 0.5 sqrt(2 / nu) chi2 = 59: reported as a
    pole that fits as well; a rise of 80 is not."""
    best = _solution(70.5, -15.4, 3189.0)
    s = np.sqrt(3189.0 / 1440.0)
    cov = Covariance(0.3, 0.3, 3e-7, 0.34, np.zeros(192), float(s), 1440.0)
    assert mirror_ambiguous(best, _solution(253.2, -17.3, 3239.0), cov)
    assert not mirror_ambiguous(best, _solution(253.2, -17.3, 3269.0), cov)
    assert ambiguity_bound(cov) == pytest.approx(0.5 * np.sqrt(2 / 1440.0) * 3189.0, rel=1e-9)
