"""Bootstrap uncertainties of the constrained unmixings near the bound (issue 25 item 4).

Reference: synthetic mixtures ``x = a S + w`` drawn here with known truth ``a`` and Gaussian
noise of known sigma (fixed seeds). A calibrated standard deviation gives standardised errors
``(a_est - a) / std`` of unit standard deviation; the issue's goal is 0.8-1.25. The case puts
many contributions near zero and two signatures 3.3 deg apart, where noise changes the
support: the support-fixed propagation gave 1.24-1.65 here (or a zero standard deviation for
an ``fcls`` epoch left with one endmember), and a median of 1.6 (up to 5) on the bench.
"""

from __future__ import annotations

import numpy as np
import pytest

from speclight.estimate.spectra.unmix_bootstrap import UPPER_QUANTILE
from speclight.estimate.spectra.unmix_checks import unmix_checks
from speclight.estimate.spectra.unmixing import unmix

B = 8
WL = np.linspace(0.0, 1.0, B)
#: a grey, a nearly grey (3 deg from it) and a red band signature [1]
S = np.array([np.full(B, 0.5), 0.45 + 0.3 * (WL - 0.5) ** 2, 0.2 + 0.6 * WL])
N = 400
SIGMA = 5e-3


def _near_bound(seed: int, method: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    share = rng.dirichlet(np.full(len(S), 0.7), size=N)  # many shares near 0
    a = share if method == "fcls" else share * rng.uniform(0.3, 1.0, (N, 1))
    x = a @ S + rng.normal(0.0, SIGMA, size=(N, B))
    truth = share if method == "nnls-norm" else a
    return truth, x, np.full((N, B), SIGMA)


@pytest.mark.parametrize("method", ["nnls", "nnls-norm", "fcls"])
def test_bootstrap_std_is_calibrated_near_the_bound(method: str) -> None:
    truth, x, sigma = _near_bound(11, method)
    est = unmix(x, S, method).abundance  # type: ignore[arg-type]
    checks = unmix_checks(x, est, S, sigma, method)
    inside = est > 0
    z = ((est - truth) / checks.abundance_std)[inside]
    assert 0.8 < np.std(z) < 1.25


def test_upper_bound_covers_the_contributions_at_zero() -> None:
    truth, x, sigma = _near_bound(12, "nnls")
    est = unmix(x, S, "nnls").abundance
    checks = unmix_checks(x, est, S, sigma, "nnls")
    assert checks.abundance_upper is not None
    pinned = est == 0
    covered = np.mean(truth[pinned] <= checks.abundance_upper[pinned])
    # conditional on the estimate being 0 the coverage falls somewhat below the quantile
    # (0.92 on the calibration bench); binomial spread of the share over ~100 zeros: 0.03
    assert pinned.sum() > 50
    assert covered > UPPER_QUANTILE - 0.1


def test_bootstrap_repeats_exactly() -> None:
    _, x, sigma = _near_bound(13, "fcls")
    est = unmix(x, S, "fcls").abundance
    first = unmix_checks(x, est, S, sigma, "fcls").abundance_std
    second = unmix_checks(x, est, S, sigma, "fcls").abundance_std
    np.testing.assert_array_equal(first, second)  # fixed seed: the same draws
