"""Unmixing's self-checks (issue 25 items 4, 5): abundance uncertainties, the misfit test
against the noise (a missing endmember), the purest-epoch extraction.

References are closed forms: synthetic mixtures ``x = a S + w`` with Gaussian noise ``w`` of
known sigma drawn here (fixed seeds). For a linear estimator the standardised errors
``(a_est - a) / std`` are N(0, 1); over ``n`` draws their sample standard deviation has the
standard error ``1 / sqrt(2 (n - 1))`` (normal theory), so 4 of them bound the test. The
chi-square of the residual with ``B - K`` degrees of freedom exceeds its 0.999 quantile with
probability 1e-3 (the definition of the quantile).
"""

from __future__ import annotations

import numpy as np
import pytest

from speclight.estimate.spectra.endmembers import extract_endmembers
from speclight.estimate.spectra.ground_truth import matched_angles_deg
from speclight.estimate.spectra.unmix_checks import unmix_checks
from speclight.estimate.spectra.unmixing import unmix

B = 8
WL = np.linspace(0.0, 1.0, B)
#: four smooth, distinct band signatures [1]
S = np.array([0.2 + 0.6 * WL, 0.8 - 0.5 * WL**2, 0.3 + 0.4 * np.sin(3 * WL), 0.5 + 0.3 * WL**3])
#: four well separated band signatures (bumps) for the extraction tests [1]
BUMPS = 0.1 + np.exp(-(((WL[None, :] - np.linspace(0, 1, 4)[:, None]) / 0.3) ** 2))
N = 2000
SIGMA = 1e-3


def _draw(seed: int, n: int = N) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    a = rng.uniform(0.2, 1.0, size=(n, len(S)))  # all present: the support is the full set
    x = a @ S + rng.normal(0.0, SIGMA, size=(n, B))
    return a, x, np.full((n, B), SIGMA)


@pytest.mark.parametrize("method", ["ls", "nnls"])
def test_abundance_std_is_calibrated(method: str) -> None:
    a, x, sigma = _draw(1)
    est = unmix(x, S, method).abundance  # type: ignore[arg-type]
    checks = unmix_checks(x, est, S, sigma, method)
    z = (est - a) / checks.abundance_std
    tolerance = 4.0 / np.sqrt(2 * (z.size - 1))
    assert abs(np.std(z) - 1.0) < tolerance


def test_fcls_std_is_calibrated() -> None:
    rng = np.random.default_rng(2)
    a = rng.dirichlet(np.full(len(S), 8.0), size=N)  # sums to one, away from the bounds
    x = a @ S + rng.normal(0.0, SIGMA, size=(N, B))
    est = unmix(x, S, "fcls").abundance
    checks = unmix_checks(x, est, S, np.full((N, B), SIGMA), "fcls")
    inside = np.all(est > 0, axis=1)
    z = ((est - a) / checks.abundance_std)[inside]
    assert abs(np.std(z) - 1.0) < 4.0 / np.sqrt(2 * (z.size - 1))


def test_misfit_rate_is_the_p_value_with_all_endmembers() -> None:
    _, x, sigma = _draw(3)
    est = unmix(x, S, "nnls").abundance
    checks = unmix_checks(x, est, S, sigma, "nnls")
    # binomial count at p = 1e-3 over N epochs: mean 2, 5 standard deviations ~ 7
    assert checks.misfit.sum() <= 2 + 5 * np.sqrt(N * 1e-3)
    assert not checks.notes()


def test_missing_endmember_is_reported() -> None:
    _, x, sigma = _draw(4, n=300)
    est = unmix(x, S[:3], "nnls-norm").abundance
    checks = unmix_checks(x, est, S[:3], sigma, "nnls-norm")
    assert checks.misfit.mean() > 0.5
    assert any("endmember is missing" in note for note in checks.notes())


def test_purest_picks_pure_faint_epochs_over_bright_mixtures() -> None:
    """Pure samples at SNR ~50 and bright mixtures 10x brighter: ATGP's largest norm is a
    mixture, the shapes' vertices are the pure samples."""
    rng = np.random.default_rng(5)
    pure = np.repeat(np.eye(len(BUMPS)), 20, axis=0) * 0.1
    mixed = rng.dirichlet(np.full(len(BUMPS), 2.0), size=400) * rng.uniform(0.5, 1.0, (400, 1))
    a = np.vstack([pure, mixed])
    sigma = np.full((len(a), B), 1e-3)
    x = a @ BUMPS + rng.normal(0.0, 1e-3, size=sigma.shape)
    angle_purest, _ = matched_angles_deg(
        BUMPS, extract_endmembers(x, 4, "purest", sigma).signatures
    )
    angle_atgp, _ = matched_angles_deg(BUMPS, extract_endmembers(x, 4, "atgp").signatures)
    # noise 1e-3 on signatures of norm ~0.15 at SNR ~50: ~1 deg per epoch, less averaged
    assert np.max(angle_purest) < 1.0
    assert np.max(angle_atgp) > 3.0


def test_purest_says_when_an_endmember_rests_on_one_epoch() -> None:
    rng = np.random.default_rng(6)
    pure = np.vstack([np.repeat(np.eye(3, 4), 10, axis=0), [[0, 0, 0, 1.0]]]) * 0.1
    mixed = rng.dirichlet(np.full(3, 2.0), size=200) @ np.eye(3, 4) * 0.1
    a = np.vstack([pure, mixed])
    sigma = np.full((len(a), B), 1e-4)
    x = a @ BUMPS + rng.normal(0.0, 1e-4, size=sigma.shape)
    found = extract_endmembers(x, 4, "purest", sigma)
    assert any("rests on 1 epoch" in note for note in found.notes)
