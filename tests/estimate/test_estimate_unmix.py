"""Linear unmixing (``speclight.estimate.spectra.unmixing``) against references it did not produce.

* hand-worked 2- and 3-band cases solved on paper (orthogonal signatures, the Euclidean
  projection onto the simplex of Duchi et al. 2008, doi:10.1145/1390156.1390191);
* the normal equations ``(S S^T) a = S x`` for least squares;
* :func:`scipy.optimize.nnls` (Lawson & Hanson's active-set algorithm) for NNLS;
* the Karush-Kuhn-Tucker conditions (the certificate of optimality of a convex problem) and a
  brute-force grid over the simplex for the fully constrained problem (Heinz & Chang 2001,
  doi:10.1109/36.911111);
* recovery of known contributions from synthetic mixtures with Gaussian noise, checked
  against the least-squares covariance ``sigma^2 (S S^T)^-1`` (Gauss-Markov).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import nnls as scipy_nnls

from speclight.errors import InputError
from speclight.estimate.spectra import unmixing as unmix_module
from speclight.estimate.spectra.unmixing import unmix

#: Round-off allowance for exact cases [m2 sr-1 or 1]: a few ulps of O(1) numbers.
EXACT = 1e-12
#: Agreement with scipy's active-set NNLS (a different algorithm, same exact optimum).
SOLVER_AGREEMENT = 1e-10


def random_signatures(rng: np.random.Generator, k: int, b: int) -> np.ndarray:
    """K band-reflectance signatures [1] of the kind a material library holds."""
    return rng.uniform(0.05, 0.9, size=(k, b))


# --- hand-worked cases -------------------------------------------------------------------


def test_exact_mixture_is_recovered_by_every_method():
    # identity signatures in 2 bands: x = (0.3, 0.7) is 0.3 of the first, 0.7 of the second
    s = np.eye(2)
    x = np.array([[0.3, 0.7]])
    for method in ("ls", "nnls", "nnls-norm", "fcls"):
        res = unmix(x, s, method)
        np.testing.assert_allclose(res.abundance, [[0.3, 0.7]], atol=EXACT)
        np.testing.assert_allclose(res.residual, [0.0], atol=EXACT)
        assert res.method == method


def test_negative_least_squares_contribution_is_clipped():
    # s1 = (1, 1), s2 = (1, -1), x = (0.2, 1.0). By hand:
    # LS:   a1 + a2 = 0.2, a1 - a2 = 1.0  ->  a = (0.6, -0.4), residual 0.
    # NNLS: a2 = 0 (a1 = 0 gives a2 = -0.4 < 0): a1 = (0.2 + 1.0) / 2 = 0.6,
    #       residual |(0.2, 1.0) - (0.6, 0.6)| = sqrt(0.32).
    # FCLS: a = (t, 1 - t), S a = (1, 2t - 1), residual^2 = 0.64 + (2 - 2t)^2 -> t = 1,
    #       residual 0.8.
    s = np.array([[1.0, 1.0], [1.0, -1.0]])
    x = np.array([[0.2, 1.0]])
    ls = unmix(x, s, "ls")
    np.testing.assert_allclose(ls.abundance, [[0.6, -0.4]], atol=EXACT)
    np.testing.assert_allclose(ls.residual, [0.0], atol=EXACT)
    nn = unmix(x, s, "nnls")
    np.testing.assert_allclose(nn.abundance, [[0.6, 0.0]], atol=EXACT)
    np.testing.assert_allclose(nn.residual, [np.sqrt(0.32)], atol=EXACT)
    norm = unmix(x, s, "nnls-norm")
    np.testing.assert_allclose(norm.abundance, [[1.0, 0.0]], atol=EXACT)
    np.testing.assert_allclose(norm.residual, [np.sqrt(0.32)], atol=EXACT)
    fc = unmix(x, s, "fcls")
    np.testing.assert_allclose(fc.abundance, [[1.0, 0.0]], atol=EXACT)
    np.testing.assert_allclose(fc.residual, [0.8], atol=EXACT)


def test_fcls_with_identity_signatures_is_the_projection_onto_the_simplex():
    # With S = I the FCLS problem is the Euclidean projection of x onto the simplex
    # (Duchi et al. 2008, fig. 1): a = max(x - theta, 0) with theta from the sorted x.
    # x = (0.5, 0.4, 0.3): all stay positive, theta = (1.2 - 1) / 3.
    # x = (0.9, 0.5, -0.4): rho = 2, theta = (0.9 + 0.5 - 1) / 2 = 0.2 -> (0.7, 0.3, 0).
    s = np.eye(3)
    x = np.array([[0.5, 0.4, 0.3], [0.9, 0.5, -0.4]])
    fc = unmix(x, s, "fcls")
    theta = 0.2 / 3
    np.testing.assert_allclose(
        fc.abundance, [[0.5 - theta, 0.4 - theta, 0.3 - theta], [0.7, 0.3, 0.0]], atol=EXACT
    )
    np.testing.assert_allclose(fc.residual, [np.sqrt(3) * theta, np.sqrt(0.24)], atol=EXACT)
    np.testing.assert_allclose(fc.abundance.sum(axis=1), 1.0, atol=EXACT)
    nn = unmix(x, s, "nnls")  # with S = I, NNLS is max(x, 0)
    np.testing.assert_allclose(nn.abundance, np.maximum(x, 0.0), atol=EXACT)
    np.testing.assert_allclose(nn.residual, [0.0, 0.4], atol=EXACT)
    norm = unmix(x, s, "nnls-norm")
    np.testing.assert_allclose(norm.abundance[1], [0.9 / 1.4, 0.5 / 1.4, 0.0], atol=EXACT)


def test_least_squares_matches_the_normal_equations():
    rng = np.random.default_rng(3)
    s = random_signatures(rng, 3, 5)
    x = rng.uniform(0.0, 1.0, size=(20, 5))
    expected = np.linalg.solve(s @ s.T, s @ x.T).T  # (S S^T) a = S x, the normal equations
    res = unmix(x, s, "ls")
    np.testing.assert_allclose(res.abundance, expected, atol=1e-10)
    np.testing.assert_allclose(
        res.residual, np.linalg.norm(x - expected @ s, axis=1), atol=SOLVER_AGREEMENT
    )


# --- independent solvers and optimality certificates -------------------------------------


@pytest.fixture
def noisy_rows() -> tuple[np.ndarray, np.ndarray]:
    """Mixtures with noise so large that many LS contributions are negative."""
    rng = np.random.default_rng(11)
    s = random_signatures(rng, 4, 10)
    a = rng.dirichlet(np.ones(4), size=300)
    x = a @ s + rng.normal(0.0, 0.15, size=(300, 10))
    return x, s


def test_nnls_agrees_with_scipy(noisy_rows):
    x, s = noisy_rows
    res = unmix(x, s, "nnls")
    ref = np.array([scipy_nnls(s.T, row)[0] for row in x])
    assert np.any(ref == 0.0), "the case must exercise the constraint"
    np.testing.assert_allclose(res.abundance, ref, atol=SOLVER_AGREEMENT)
    ref_r = np.array([scipy_nnls(s.T, row)[1] for row in x])
    np.testing.assert_allclose(res.residual, ref_r, atol=SOLVER_AGREEMENT)


def kkt_violation(x: np.ndarray, s: np.ndarray, a: np.ndarray, sum_to_one: bool) -> float:
    """Largest violation of the KKT conditions of min |x - S a|^2, a >= 0 (, sum a = 1).

    With g = S (S^T a - x) (half the gradient) the conditions are g_i = mu where a_i > 0 and
    g_i >= mu where a_i = 0, with mu = 0 without the sum constraint (its multiplier otherwise).
    """
    g = (a @ s - x) @ s.T
    active = a > 1e-12
    worst = 0.0
    for gi, ai in zip(g, active, strict=True):
        mu = float(np.mean(gi[ai])) if sum_to_one else 0.0
        worst = max(worst, float(np.max(np.abs(gi[ai] - mu), initial=0.0)))
        worst = max(worst, float(np.max(mu - gi[~ai], initial=0.0)))
    return worst


def test_fcls_satisfies_the_kkt_conditions(noisy_rows):
    x, s = noisy_rows
    res = unmix(x, s, "fcls")
    assert np.all(res.abundance >= 0.0)
    np.testing.assert_allclose(res.abundance.sum(axis=1), 1.0, atol=EXACT)
    assert np.any(res.abundance == 0.0), "the case must exercise the non-negativity"
    assert kkt_violation(x, s, res.abundance, sum_to_one=True) < 1e-10
    nn = unmix(x, s, "nnls")
    assert kkt_violation(x, s, nn.abundance, sum_to_one=False) < 1e-10


def test_fcls_is_not_beaten_by_any_point_of_a_simplex_grid():
    # brute force: every point of a 1/200 grid over the 3-endmember simplex
    rng = np.random.default_rng(5)
    s = random_signatures(rng, 3, 10)
    x = rng.dirichlet(np.ones(3), size=8) @ s + rng.normal(0.0, 0.1, size=(8, 10))
    x[0] = -s[1]  # far outside: the optimum is on the boundary
    m = 200
    i, j = np.meshgrid(np.arange(m + 1), np.arange(m + 1), indexing="ij")
    keep = i + j <= m
    grid = np.stack([i[keep], j[keep], m - i[keep] - j[keep]], axis=1) / m
    grid_r = np.linalg.norm(x[:, None, :] - (grid @ s)[None], axis=2).min(axis=1)
    res = unmix(x, s, "fcls")
    # no grid point does better, and the best one is within one grid step of the optimum
    # (|d residual| <= |S^T d a| <= |S| |d a| with |d a| <= sqrt(2) / m)
    step = np.linalg.norm(s, 2) * np.sqrt(2.0) / m
    assert np.all(res.residual <= grid_r + EXACT)
    assert np.all(grid_r - res.residual <= step)


def test_per_epoch_solver_agrees_with_the_enumeration(noisy_rows, monkeypatch):
    x, s = noisy_rows
    exact = {m: unmix(x, s, m) for m in ("nnls", "fcls")}
    monkeypatch.setattr(unmix_module, "MAX_ENUMERATED_ENDMEMBERS", 0)
    nn = unmix(x, s, "nnls")
    np.testing.assert_allclose(nn.abundance, exact["nnls"].abundance, atol=SOLVER_AGREEMENT)
    fc = unmix(x, s, "fcls")
    # the augmented row of weight w = FCLS_SUM_WEIGHT |S| leaves sum(a) - 1 of order
    # |x - S a| |S| / w^2 = |x - S a| / (FCLS_SUM_WEIGHT^2 |S|); here |x - S a| < 2, |S| > 1
    tol = 2.0 / unmix_module.FCLS_SUM_WEIGHT**2
    np.testing.assert_allclose(fc.abundance, exact["fcls"].abundance, atol=tol)
    np.testing.assert_allclose(fc.abundance.sum(axis=1), 1.0, atol=tol)


# --- recovery from synthetic mixtures with noise -----------------------------------------

N_RECOVERY = 4000
SIGMA = 0.002  # noise per band [m2 sr-1]


@pytest.fixture
def mixtures() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """4 signatures over 10 bands, contributions well inside the simplex, Gaussian noise."""
    rng = np.random.default_rng(2024)
    s = random_signatures(rng, 4, 10)
    a = rng.dirichlet(np.full(4, 30.0), size=N_RECOVERY)
    x = a @ s + rng.normal(0.0, SIGMA, size=(N_RECOVERY, 10))
    return x, s, a


def mahalanobis_mean(err: np.ndarray, cov: np.ndarray) -> float:
    """Mean of e^T C^+ e over the rows (chi-square with rank(C) degrees of freedom)."""
    return float(np.mean(np.einsum("nk,kl,nl->n", err, np.linalg.pinv(cov), err)))


def chi2_mean_bound(dof: int, n: int) -> float:
    """Five standard errors of the mean of n chi-square(dof) draws, sqrt(2 dof / n)."""
    return 5.0 * np.sqrt(2.0 * dof / n)


def test_least_squares_errors_follow_the_gauss_markov_covariance(mixtures):
    x, s, a = mixtures
    res = unmix(x, s, "ls")
    cov = SIGMA**2 * np.linalg.inv(s @ s.T)
    err = res.abundance - a
    assert abs(mahalanobis_mean(err, cov) - 4) < chi2_mean_bound(4, N_RECOVERY)
    # unbiased: each component's mean error within 5 standard errors
    assert np.all(np.abs(err.mean(axis=0)) < 5.0 * np.sqrt(np.diag(cov) / N_RECOVERY))
    # the residual norm^2 is sigma^2 chi-square(B - K)
    assert abs(np.mean(res.residual**2) / SIGMA**2 - 6) < chi2_mean_bound(6, N_RECOVERY)


def test_nnls_equals_least_squares_where_that_is_non_negative(mixtures):
    x, s, _ = mixtures
    ls = unmix(x, s, "ls").abundance
    nn = unmix(x, s, "nnls").abundance
    inside = np.all(ls >= 0.0, axis=1)
    assert inside.mean() > 0.99  # the contributions are well inside the simplex
    np.testing.assert_allclose(nn[inside], ls[inside], atol=1e-10)
    assert np.all(nn >= 0.0)


def test_fcls_errors_follow_the_equality_constrained_covariance(mixtures):
    # With sum(a) = 1 imposed (and a >= 0 inactive) the estimator is the equality-constrained
    # least squares, covariance sigma^2 (G^-1 - G^-1 1 1^T G^-1 / 1^T G^-1 1), G = S S^T,
    # of rank K - 1.
    x, s, a = mixtures
    res = unmix(x, s, "fcls")
    g_inv = np.linalg.inv(s @ s.T)
    u = g_inv.sum(axis=1)
    cov = SIGMA**2 * (g_inv - np.outer(u, u) / u.sum())
    assert abs(mahalanobis_mean(res.abundance - a, cov) - 3) < chi2_mean_bound(3, N_RECOVERY)
    np.testing.assert_allclose(res.abundance.sum(axis=1), 1.0, atol=EXACT)


def test_nnls_norm_recovers_fractions_whatever_the_overall_scale(mixtures):
    # c x = c (a S + w) with an unknown scale c (an area [m2 sr-1]); NNLS gives c a + e with
    # e ~ N(0, (c sigma)^2 G^-1) and the normalised a' = (c a + e) / sum(c a + e) is, to first
    # order, a + J e / c with J = I - a 1^T: covariance sigma^2 J G^-1 J^T, of rank K - 1.
    x, s, a = mixtures
    c = 3.7
    res = unmix(c * x, s, "nnls-norm")
    np.testing.assert_allclose(res.abundance.sum(axis=1), 1.0, atol=EXACT)
    g_inv = np.linalg.inv(s @ s.T)
    err = res.abundance - a
    d2 = np.empty(len(a))
    for n, (an, en) in enumerate(zip(a, err, strict=True)):
        j = np.eye(4) - np.outer(an, np.ones(4))
        cov = SIGMA**2 * j @ g_inv @ j.T
        d2[n] = en @ np.linalg.pinv(cov) @ en
    assert abs(d2.mean() - 3) < chi2_mean_bound(3, N_RECOVERY)


# --- batch failures and bad inputs -------------------------------------------------------


def test_non_finite_rows_give_nan_rows_and_leave_the_others_alone(noisy_rows):
    x, s = noisy_rows
    bad = x.copy()
    bad[3, 2] = np.nan
    bad[7, 0] = np.inf
    for method in ("ls", "nnls", "nnls-norm", "fcls"):
        clean = unmix(x, s, method)
        res = unmix(bad, s, method)
        assert np.all(np.isnan(res.abundance[[3, 7]])) and np.all(np.isnan(res.residual[[3, 7]]))
        keep = np.setdiff1d(np.arange(len(x)), [3, 7])
        np.testing.assert_allclose(res.abundance[keep], clean.abundance[keep], atol=EXACT)
        np.testing.assert_allclose(res.residual[keep], clean.residual[keep], atol=EXACT)


def test_nnls_norm_of_an_all_zero_fit_is_nan():
    s = np.eye(2)
    res = unmix(np.array([[-0.1, -0.2], [0.1, 0.3]]), s, "nnls-norm")
    assert np.all(np.isnan(res.abundance[0]))
    np.testing.assert_allclose(res.residual[0], np.hypot(0.1, 0.2), atol=EXACT)
    np.testing.assert_allclose(res.abundance[1], [0.25, 0.75], atol=EXACT)


def test_no_epochs_give_empty_results():
    res = unmix(np.empty((0, 3)), np.eye(3), "fcls")
    assert res.abundance.shape == (0, 3) and res.residual.shape == (0,)


@pytest.mark.parametrize(
    ("x", "signatures", "method", "field", "words"),
    [
        (np.ones(3), np.eye(3), "fcls", "x", "x[None, :]"),
        (np.ones((2, 3, 1)), np.eye(3), "fcls", "x", "(N, B)"),
        ([["a", "b"]], np.eye(2), "fcls", "x", "numeric"),
        (np.ones((2, 3)), np.eye(4)[:2], "fcls", "signatures", "x has 3"),
        (np.ones((2, 3)), np.ones((4, 3)), "fcls", "signatures", "more than the 3 bands"),
        (np.ones((2, 3)), [[1, 0, 0], [2, 0, 0]], "fcls", "signatures", "linearly dependent"),
        (np.ones((2, 3)), [[1, 0, np.nan]], "fcls", "signatures", "signatures[0, 2]"),
        (np.ones((2, 3)), np.empty((0, 3)), "fcls", "signatures", "empty"),
        (np.ones((2, 3)), np.eye(3), "fcsl", "method", "did you mean 'fcls'"),
    ],
)
def test_bad_inputs_raise_input_error_naming_the_argument(x, signatures, method, field, words):
    with pytest.raises(InputError, match=field) as info:
        unmix(x, signatures, method)
    assert info.value.field == field
    assert words in str(info.value)
    assert isinstance(info.value, ValueError)
