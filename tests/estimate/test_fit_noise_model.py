"""The fit's likelihood and what it says about its data (issue 25): the model's own Poisson
noise instead of the measured rate's (no Neyman bias), outliers left out and named, a misfit
far above the noise reported.

References: the Poisson maximum-likelihood scale of a model ``s c`` without background is
``sum m / sum c`` in closed form (the score equation ``sum (n - s c T) / s = 0``; McCullagh
& Nelder 1989, section 6.2); its variance is ``s / (T sum c)`` (the inverse Fisher
information); Neyman's chi-square (sigma from the measured counts) is biased low by about
one count per epoch of the sum (Mighell 1999, doi:10.1086/307253).
"""

import numpy as np
import pytest

from speclight.estimate.fitting.fit import fit_scales, shot_noise_sigma
from speclight.estimate.fitting.fit_quality import clipped_scales, misfit_text, outlier_text
from speclight.estimate.fitting.noise_model import Likelihood, PoissonNoise

T_EXP_S = 0.5
N_EPOCHS = 400
MODEL = np.column_stack([np.full(N_EPOCHS, 20.0), 20.0 + 8.0 * np.sin(np.arange(N_EPOCHS))])


def test_poisson_scale_is_the_closed_form_maximum_likelihood_scale():
    rng = np.random.default_rng(1)
    m = rng.poisson(MODEL * 0.7 * T_EXP_S) / T_EXP_S
    fit = fit_scales(MODEL, m, PoissonNoise.of(m.shape, T_EXP_S))
    np.testing.assert_allclose(fit.scale, m.sum(0) / MODEL.sum(0), rtol=1e-10)
    # Fisher information sum c^2 T^2 / lambda = T sum c / s at the fit: std sqrt(s / (T sum c))
    # (inflated only when the deviance exceeds its degrees of freedom)
    inflate = np.maximum(1.0, fit.chi2 / (N_EPOCHS - 1))
    expected = np.sqrt(fit.scale / (T_EXP_S * MODEL.sum(0)) * inflate)
    np.testing.assert_allclose(fit.scale_std, expected, rtol=1e-6)


def test_poisson_scales_are_unbiased_where_neyman_weights_are_not():
    # 4 to 10 electrons per epoch: the Neyman fit is biased low by about one count in the sum
    # per epoch (-10 % and more); the Poisson fit's mean over 200 draws is within 4 standard
    # errors of the truth
    truth, rng = 0.7, np.random.default_rng(2)
    poisson, neyman = [], []
    for _ in range(200):
        m = rng.poisson(MODEL * truth * T_EXP_S) / T_EXP_S
        poisson.append(fit_scales(MODEL, m, PoissonNoise.of(m.shape, T_EXP_S)).scale)
        neyman.append(fit_scales(MODEL, m, shot_noise_sigma(m, T_EXP_S)).scale)
    poisson, neyman = np.array(poisson), np.array(neyman)
    standard_error = poisson.std(0, ddof=1) / np.sqrt(len(poisson))
    assert np.all(np.abs(poisson.mean(0) - truth) < 4 * standard_error)
    assert np.all(neyman.mean(0) < truth - 10 * standard_error)  # the bias this fixes


def test_a_misplaced_glint_does_not_drive_the_scale_to_zero():
    # the model glints where the data are dark and the data glint where the model is dark
    # (issue 25: albedo 0.0005 for 0.7): the Poisson scale matches the total counts
    dark, glint = np.full(100, 50.0), np.full(100, 50.0)
    glint[40:45] = 5e5
    model, measured = dark.copy(), dark.copy()
    model[40:45] = 5e5
    measured[60:65] = 5e5 * 0.7
    m = np.round(measured * T_EXP_S)[:, None] / T_EXP_S
    fit = fit_scales(model[:, None], m, PoissonNoise.of(m.shape, T_EXP_S))
    assert fit.scale[0] == pytest.approx(m.sum() / model.sum(), rel=1e-9)
    neyman = fit_scales(model[:, None], m, shot_noise_sigma(m, T_EXP_S))
    assert neyman.scale[0] < 0.01  # the failure
    assert fit.scale[0] > 0.5


def test_a_cosmic_ray_is_left_out_named_and_does_not_widen_the_std():
    rng = np.random.default_rng(3)
    sigma = np.full(MODEL.shape, 1.0)
    clean = 0.7 * MODEL + sigma * rng.standard_normal(MODEL.shape)
    hit = clean.copy()
    hit[123, 1] += 100.0  # +100 sigma in one band at one epoch
    like = Likelihood(hit, sigma)
    plain, kept = clipped_scales(like, MODEL, None)
    fit, drop = clipped_scales(like, MODEL, 5.0)
    assert np.argwhere(drop).tolist() == [[123, 1]]
    reference = fit_scales(np.where(drop, np.nan, MODEL), hit, sigma)  # fitted without it
    np.testing.assert_allclose(fit.scale, reference.scale, rtol=1e-12)
    np.testing.assert_allclose(fit.scale_std, reference.scale_std, rtol=1e-12)
    assert plain.scale_std[1] > 3 * fit.scale_std[1]  # what clipping prevents
    assert not kept.any()
    times = np.datetime64("2020-01-01T00:00:00", "ns") + np.arange(N_EPOCHS) * np.timedelta64(
        1, "s"
    )
    text = outlier_text(drop, times, ["B", "R"], 5.0)
    assert text.startswith("1 measurement(s) more than 5 robust sigmas") and "R at" in text


def test_clean_data_lose_nothing_and_a_model_that_misfits_everywhere_keeps_its_data():
    rng = np.random.default_rng(4)
    sigma = np.full(MODEL.shape, 1.0)
    clean = 0.7 * MODEL + sigma * rng.standard_normal(MODEL.shape)
    _, drop = clipped_scales(Likelihood(clean, sigma), MODEL, 5.0)
    assert not drop.any()
    assert misfit_text(float(np.sum((clean - 0.7 * MODEL) ** 2)), clean.size, 2) == ""
    # a wrong model shape: residuals of tens of sigma everywhere, but not outliers
    wrong = np.column_stack([MODEL[:, 0], np.roll(MODEL[:, 1], 1)])
    fit, drop = clipped_scales(Likelihood(clean, sigma), wrong, 5.0)
    assert drop.sum() < 0.01 * drop.size
    text = misfit_text(float(np.sum(fit.chi2)), clean.size, 2)
    assert text.startswith("the model misfits the data: chi-square per degree of freedom")
