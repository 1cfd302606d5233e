"""Covariance estimators of the tumbling state (hac_covariance.py, tumbling_uncertainty.py)
against closed forms: a toy nonlinear least-squares problem whose estimate's covariance is
known, and the propagation to the summary against sampling."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import least_squares

from speclight.estimate.shape.tumbling_principal import lag1_correlation
from speclight.estimate.shape.tumbling_uncertainty import (
    SUMMARY,
    bartlett_bandwidth,
    block_jackknife_covariance,
    excess_share,
    hac_covariance,
    momentum_basis,
    momentum_direction,
    parameter_covariance,
    state_std,
    state_summary,
)

# y = A sin(t + c) + noise over ten cycles: nonlinear in the phase c, every block of the
# jackknife about as informative as the others
T = np.linspace(0.0, 20 * np.pi, 200)
A_TRUE, K_TRUE, SIGMA = 2.0, 0.3, 0.05
N_DRAWS = 300
N_BLOCKS = 20


def _model(x: np.ndarray) -> np.ndarray:
    return np.asarray(x[0] * np.sin(T + x[1]))


def _jacobian(a: float, c: float) -> np.ndarray:
    """Closed-form Jacobian of the residuals (y - A sin(t + c)) / sigma over (A, c)."""
    return -np.stack([np.sin(T + c), a * np.cos(T + c)], axis=1) / SIGMA


def _ar1(rng: np.random.Generator, phi: float) -> np.ndarray:
    """AR(1) noise of unit marginal variance."""
    e = rng.normal(size=T.size) * np.sqrt(1 - phi**2)
    e[0] = rng.normal()
    for i in range(1, T.size):
        e[i] += phi * e[i - 1]
    return e


def _draws(phi: float):
    """Fits of N_DRAWS noise draws: the estimates and each estimator's variances."""
    rng = np.random.default_rng(7)
    est, hac, jack = [], [], []
    for _ in range(N_DRAWS):
        y = _model(np.array([A_TRUE, K_TRUE])) + SIGMA * _ar1(rng, phi)
        res = least_squares(
            lambda x, y=y: (y - _model(x)) / SIGMA,
            [A_TRUE, K_TRUE],
            jac=lambda x, y=y: _jacobian(x[0], x[1]),
        )
        est.append(res.x)
        hac.append(np.diag(hac_covariance(res.jac, res.fun)))
        jack.append(np.diag(block_jackknife_covariance(res.jac, res.fun, N_BLOCKS)))
    return np.array(est), np.array(hac), np.array(jack)


@pytest.mark.parametrize("phi", [0.0, 0.5])
def test_estimators_against_the_closed_form_covariance(phi):
    # Reference: the linearised least-squares estimate's covariance under noise of
    # covariance S (S_ij = phi^|i-j|, in units of sigma): B^-1 J^T S J B^-1, B = J^T J
    # (e.g. Seber & Wild 2003, Nonlinear Regression, sec. 2.1 and 6.1), with the Jacobian
    # in closed form at the truth.
    j = _jacobian(A_TRUE, K_TRUE)
    lag = np.abs(np.arange(T.size)[:, None] - np.arange(T.size)[None, :])
    bread = np.linalg.inv(j.T @ j)
    truth = np.diag(bread @ j.T @ phi**lag @ j @ bread)
    est, hac, jack = _draws(phi)
    # the Monte Carlo agrees with the closed form (sample variance's relative standard
    # error sqrt(2 / N); 4 of them)
    assert np.all(np.abs(np.var(est, axis=0, ddof=1) / truth - 1) < 4 * np.sqrt(2 / N_DRAWS))
    # Each estimator's mean variance: within 4 standard errors of the mean plus its
    # leading bias for an AR(1) (Kunsch 1989; Newey & West 1987): the lags it leaves out
    # or down-weights, 2 phi / (L (1 - phi^2)) of the long-run variance, with L the block
    # length (jackknife) or the Bartlett bandwidth at the true phi (the sandwich), and the
    # share the fit absorbs, p / n_eff, n_eff = n (1 - phi) / (1 + phi) independent points.
    for name, var, length in (
        ("sandwich", hac, bartlett_bandwidth(phi, T.size)),
        ("jackknife", jack, T.size / N_BLOCKS),
    ):
        bias = 2 * phi / (length * (1 - phi**2)) + 2 / (T.size * (1 - phi) / (1 + phi))
        se = np.std(var, axis=0, ddof=1) / np.sqrt(N_DRAWS) / truth
        ratio = np.mean(var, axis=0) / truth
        assert np.all(np.abs(ratio - 1) < bias + 4 * se), (name, ratio, bias, se)


def test_white_noise_ratio_without_lags():
    # With no lags (bandwidth 1) and constant residuals of size s the sandwich is White's
    # HC1, which for r_i = s reduces to s^2 (J^T J)^-1 n / (n - p) (MacKinnon & White 1985).
    j = _jacobian(A_TRUE, K_TRUE)
    s = 1.7
    cov = hac_covariance(j, np.full(T.size, s), bandwidth=1.0)
    expected = s**2 * np.linalg.inv(j.T @ j) * T.size / (T.size - 2)
    np.testing.assert_allclose(cov, expected, rtol=1e-9)


def test_bandwidth_follows_andrews():
    # Andrews (1991) eq. 6.4 for an AR(1): alpha = 4 rho^2 / ((1 - rho)^2 (1 + rho)^2);
    # rho = 0.5: alpha = 1 / (0.25 * 2.25) = 16 / 9, S = 1.1447 (16 n / 9)^(1/3).
    assert bartlett_bandwidth(0.5, 200) == pytest.approx(1.1447 * (16 / 9 * 200) ** (1 / 3))
    assert bartlett_bandwidth(-0.3, 200) == 1.0  # no negative correlation counted


def test_excess_share_is_zero_at_the_noise_floor():
    rng = np.random.default_rng(3)
    r = rng.normal(size=500)
    assert excess_share(r, 8) == 0.0  # chi2 ~ 500 below its 99 % point (~571)
    # three times the noise: chi2 ~ 4500, share 1 - 571 / 4500
    assert excess_share(3 * r, 8) == pytest.approx(1 - 571.0 / np.sum(9 * r**2), abs=0.01)
    assert lag1_correlation(r) < 0.15


def test_momentum_basis_is_east_and_north():
    # east = d(direction) / d(longitude) normalised = (-sin l, cos l, 0); north completes
    # the right-handed set (direction, east, north) and points to +z.
    lon, lat = np.deg2rad(40.0), np.deg2rad(25.0)
    d = np.array([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)])
    east, north = momentum_basis(d)
    np.testing.assert_allclose(east, [-np.sin(lon), np.cos(lon), 0.0], atol=1e-12)
    np.testing.assert_allclose(
        north, [-np.sin(lat) * np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat)], atol=1e-12
    )


def test_state_std_against_sampling():
    # The propagation (central differences) against the spread of the summary over states
    # drawn from the same covariance: relative standard error of a sample standard deviation
    # sqrt(1 / (2 N)); 4 of them, plus the covariance's small nonlinearity.
    rng = np.random.default_rng(11)
    x = np.array([0.3, -1.1, 0.7, 0.012, 0.025, -0.018, 0.4, -0.6])
    jac = rng.normal(size=(120, 8)) * np.array([300, 300, 300, 3e4, 3e4, 3e4, 100, 100])
    residuals = rng.normal(size=120)
    std = state_std(x, jac, residuals, "scalar", 0.0)
    cov = parameter_covariance(jac, residuals, "scalar", 0.0)
    east, north = momentum_basis(momentum_direction(x))
    n = 4000
    samples = x + rng.multivariate_normal(np.zeros(8), cov, size=n)
    spread = np.std([state_summary(s, east, north) for s in samples], axis=0, ddof=1)
    assert len(std) == len(SUMMARY)
    np.testing.assert_allclose(std, spread, rtol=4 * np.sqrt(1 / (2 * n)) + 0.01)


def test_unknown_method_names_the_choices():
    j = _jacobian(A_TRUE, K_TRUE)
    with pytest.raises(ValueError, match=r"method = 'bootstrap'.*jackknife"):
        parameter_covariance(j, np.ones(T.size), "bootstrap")  # type: ignore[arg-type]
