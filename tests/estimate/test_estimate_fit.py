"""The plain-array core of ``speclight fit`` (issue 10, item 2): scales and roughness.

References: a weighted least-squares case worked by hand; the Poisson variance of a count
(n electrons: variance n); the spread of the fitted roughness over many noise draws (Monte
Carlo), against which the reported standard deviation (J^T W J)^-1 is checked; and the
known parameters of simulated noisy data.
"""

import numpy as np
import pytest

from speclight.estimate.fitting.fit import fit_scales, shot_noise_sigma
from speclight.estimate.fitting.roughness_fit import fit_roughness


def test_scales_match_a_hand_worked_weighted_least_squares_case():
    # Band 0: c = 1, 2, 3; m = 2, 3, 7; sigma = 1, 1, 2 -> w = 1, 1, 1/4.
    # sum w m c = 2 + 6 + 21/4 = 53/4; sum w c^2 = 1 + 4 + 9/4 = 29/4 -> s = 53/29.
    # chi2 = (2 - 53/29)^2 + (3 - 106/29)^2 + (7 - 159/29)^2 / 4 = 30/29 (< dof 2: no
    # inflation) -> std = sqrt(1 / (29/4)) = 2/sqrt(29).
    # Band 1: c = 1, 1, 1; m = 0, 2, 4; sigma 1 -> s = 2, chi2 = 8, dof 2 -> the variance
    # 1/3 is inflated by chi2/dof = 4: std = 2/sqrt(3).
    c = np.array([[1.0, 1.0], [2.0, 1.0], [3.0, 1.0]])
    m = np.array([[2.0, 0.0], [3.0, 2.0], [7.0, 4.0]])
    s = np.array([[1.0, 1.0], [1.0, 1.0], [2.0, 1.0]])
    fit = fit_scales(c, m, s)
    np.testing.assert_allclose(fit.scale, [53 / 29, 2.0], rtol=1e-14)
    np.testing.assert_allclose(fit.chi2, [30 / 29, 8.0], rtol=1e-12)
    np.testing.assert_allclose(fit.scale_std, [2 / np.sqrt(29), 2 / np.sqrt(3)], rtol=1e-12)
    np.testing.assert_array_equal(fit.n_used, [3, 3])


def test_scales_skip_nan_and_flag_an_empty_band():
    c = np.array([[1.0, 1.0], [2.0, 0.0], [np.nan, 0.0]])
    m = np.array([[2.0, np.nan], [4.0, 1.0], [5.0, 1.0]])
    fit = fit_scales(c, m, np.ones_like(c))
    assert fit.scale[0] == pytest.approx(2.0, rel=1e-14)  # the NaN model row is skipped
    assert fit.n_used[0] == 2
    assert np.isnan(fit.scale[1]) and np.isnan(fit.scale_std[1])  # model zero where measured


def test_shot_noise_is_the_poisson_sigma_of_the_electrons_with_a_floor():
    # 400 s-1 for 0.5 s, 2 exposures averaged: 400 electrons, sigma sqrt(400) / 1 s = 20 s-1.
    rate = np.array([[400.0, -3.0], [0.0, np.nan]])
    sigma = shot_noise_sigma(rate, 0.5, np.array([2, 1]))
    assert sigma[0, 0] == pytest.approx(20.0, rel=1e-14)
    assert sigma[0, 1] == pytest.approx(1.0)  # floor: one electron in 1 s -> 1 s-1
    assert sigma[1, 0] == pytest.approx(2.0)  # one electron in 0.5 s -> 2 s-1
    assert np.isnan(sigma[1, 1])


T = np.linspace(-1.0, 1.0, 201)
GAIN = np.array([1000.0, 400.0])


def _glint(alpha):
    """A glint of width alpha on a baseline, in two bands (N, 2)."""
    shape = np.exp(-0.5 * (T / alpha[0]) ** 2) + 0.05
    return shape[:, None] * GAIN[None, :]


def test_roughness_and_scales_are_recovered_and_the_std_matches_the_monte_carlo_spread():
    truth_alpha, truth_scale = 0.12, np.array([0.8, 1.3])
    clean = _glint(np.array([truth_alpha])) * truth_scale
    sigma = np.sqrt(clean)  # Gaussian noise of Poisson size
    rng = np.random.default_rng(7)
    alphas, stds, calls = [], [], []

    def model(alpha):
        calls.append(float(alpha[0]))
        return _glint(alpha)

    for _ in range(40):
        m = clean + sigma * rng.standard_normal(clean.shape)
        calls.clear()
        fit = fit_roughness(model, m, sigma, np.array([0.3]), (0.01, 1.0))
        assert fit.success, fit.message
        assert len(calls) == len(set(calls)) == fit.n_simulations  # each value once
        alphas.append(fit.roughness[0])
        stds.append(fit.roughness_std[0])
        assert np.all(np.abs(fit.scales.scale - truth_scale) < 5 * fit.scales.scale_std)
    alphas, stds = np.array(alphas), np.array(stds)
    spread = alphas.std(ddof=1)
    # the mean of 40 draws is within 4 standard errors of the truth
    assert abs(alphas.mean() - truth_alpha) < 4 * spread / np.sqrt(40)
    # the reported std agrees with the spread; the sample std of 40 draws is uncertain by
    # about 1/sqrt(2 * 39) = 11 %, so 3 of those (35 %) bound the ratio
    assert np.median(stds) / spread == pytest.approx(1.0, abs=0.35)


def test_a_roughness_the_data_cannot_see_gets_a_huge_std():
    # a model whose shape does not depend on alpha, only its size: alpha is degenerate with
    # the scales, as the roughness of a polished sphere is with its albedo
    def model(alpha):
        return _glint(np.array([0.2])) * (1.0 + alpha[0])

    m = model(np.array([0.5])) * 0.9
    fit = fit_roughness(model, m, np.sqrt(m), np.array([0.3]), (0.01, 1.0))
    assert not np.isfinite(fit.roughness_std[0]) or fit.roughness_std[0] > 0.99
    assert "changes the light curve not at all or only in brightness" in fit.unconstrained[0]


def test_fixed_scales_fit_roughness_alone():
    m = _glint(np.array([0.2]))
    fit = fit_roughness(_glint, m, np.sqrt(m), np.array([0.5]), (0.01, 1.0), fit_scale=False)
    assert fit.roughness[0] == pytest.approx(0.2, abs=1e-3)
    np.testing.assert_array_equal(fit.scales.scale, [1.0, 1.0])
