"""Noisy measurements against Poisson/Gaussian statistics; sky background conversion."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from speclight.errors import InputError
from speclight.instrument import band_response, simulate_measurement, sky_count_rate_per_s

N_SAMPLES = 40_000
Z_MAX = 4.5  # two-sided p ~ 7e-6 per check at a fixed seed: a real bias fails, noise does not


def test_sample_mean_and_variance_match_poisson_plus_read_noise() -> None:
    signal = np.array([3.0, 40.0, 2500.0])  # s-1: photon-starved to bright
    sky, dark, read, t = np.array([1.5, 10.0, 30.0]), 0.7, 4.0, 2.0
    rates = np.tile(signal, (N_SAMPLES, 1))
    m = simulate_measurement(
        rates, t, sky_count_rate_per_s=sky, dark_current_e_per_s=dark, read_noise_e=read, seed=7
    )
    # Background-subtracted rate: mean S; variance ((S + B + D) t + sigma_r^2) / t^2.
    var = ((signal + sky + dark) * t + read**2) / t**2
    mean_se = np.sqrt(var / N_SAMPLES)
    assert np.all(np.abs(m.mean(axis=0) - signal) < Z_MAX * mean_se)
    # Standard error of the sample variance: sqrt((mu4 - var^2 (n-3)/(n-1)) / n), with the
    # fourth central moment of Poisson(lam) + Normal(0, s): lam + 3 lam^2 + 6 lam s^2 + 3 s^4,
    # scaled by 1/t^4.
    lam = (signal + sky + dark) * t
    mu4 = (lam + 3 * lam**2 + 6 * lam * read**2 + 3 * read**4) / t**4
    var_se = np.sqrt((mu4 - var**2 * (N_SAMPLES - 3) / (N_SAMPLES - 1)) / N_SAMPLES)
    assert np.all(np.abs(m.var(axis=0, ddof=1) - var) < Z_MAX * var_se)


def test_pure_shot_noise_is_integer_poisson() -> None:
    m = simulate_measurement(np.full((N_SAMPLES, 1), 2.5), 1.0, seed=1)
    counts = m[:, 0]
    assert np.all(counts == np.round(counts))  # whole photo-electrons
    # P(0) of Poisson(2.5) = exp(-2.5); binomial standard error.
    p0 = np.exp(-2.5)
    assert abs(np.mean(counts == 0) - p0) < Z_MAX * np.sqrt(p0 * (1 - p0) / N_SAMPLES)


def test_seed_reproducible_and_nan_rows_kept() -> None:
    rates = np.array([[10.0, 20.0], [np.nan, np.nan]])
    a = simulate_measurement(rates, 1.0, seed=3)
    b = simulate_measurement(rates, 1.0, seed=3)
    assert np.array_equal(a[0], b[0]) and np.isnan(a[1]).all()
    with pytest.raises(InputError, match="exposure_s"):
        simulate_measurement(rates, 0.0)
    with pytest.raises(InputError, match="read_noise_e"):
        simulate_measurement(rates, 1.0, read_noise_e=-1.0)


def test_sky_rate_from_surface_brightness_closed_form() -> None:
    # A sky of mu AB mag arcsec-2 over Omega arcsec2 is f_nu = 3631 Jy 10^(-0.4 mu) Omega.
    # Photon rate through a Gaussian band with unit efficiency:
    # A f_nu / h * integral R(lambda) / lambda dlambda (f_lambda = f_nu c / lambda^2).
    # Reference integral by scipy quad on the continuous Gaussian.
    h = 6.62607015e-34
    wl = np.arange(300.0, 1241.0, 5.0)
    area, mu, radius = 0.145, 21.0, 3.0
    omega = np.pi * radius**2

    def integrand(lam: float) -> float:
        return np.exp(-0.5 * ((lam - 550.0) / 40.0) ** 2) / lam

    integral, _ = quad(integrand, 300.0, 1240.0)
    exact = area * 3631e-26 * 10 ** (-0.4 * mu) * omega / h * integral
    got = sky_count_rate_per_s(
        mu,
        area,
        wl,
        np.ones(wl.size),
        np.ones(wl.size),
        band_response(["G-550/40"], wl),
        background_aperture_radius_arcsec=radius,
    )
    # Bin-sum vs quad: Gaussian averaged exactly per bin, 1/lambda sampled at the centre:
    # relative error (5 nm)^2/24 * 2/lambda^2 ~ 1e-5.
    assert got[0] == pytest.approx(exact, rel=1e-4)
    with pytest.raises(InputError, match="exactly one"):
        sky_count_rate_per_s(
            mu, area, wl, np.ones(wl.size), np.ones(wl.size), band_response(["G-550/40"], wl)
        )


def test_dark_current_1e300_does_not_overflow_the_poisson_draw() -> None:
    # fuzz/0246-noise-dark-current-1e300: numpy's poisson refuses lam > ~9.2e18 (ValueError)
    rates = np.array([[5.0, 5.0]])
    m = simulate_measurement(rates, 1.0, dark_current_e_per_s=1e300, seed=2)
    assert np.all(np.isfinite(m))
    faint = simulate_measurement(np.full((N_SAMPLES, 1), 2.5), 1.0, seed=1)[:, 0]
    assert np.all(faint == np.round(faint))  # below the threshold: still integer Poisson


def test_normal_approximation_has_the_poisson_moments() -> None:
    # Above POISSON_MAX_MEAN the count is N(lam, lam): mean lam and variance lam are those of
    # Poisson(lam); the Z-tests as in test_sample_mean_and_variance_match_poisson_plus_read_noise
    # (read noise 0, so the fourth central moment is lam + 3 lam^2).
    from speclight.instrument.noise import POISSON_MAX_MEAN

    t = 1.0
    # just below (numpy's Poisson), above, above numpy's 9.2e18 limit
    for lam in (POISSON_MAX_MEAN * 0.999, POISSON_MAX_MEAN * 1e4, 1e20):
        m = simulate_measurement(np.full((N_SAMPLES, 1), lam), t, seed=11)[:, 0]
        mean_se = np.sqrt(lam / N_SAMPLES)
        assert abs(m.mean() - lam) < Z_MAX * mean_se
        mu4 = lam + 3 * lam**2
        var_se = np.sqrt((mu4 - lam**2 * (N_SAMPLES - 3) / (N_SAMPLES - 1)) / N_SAMPLES)
        assert abs(m.var(ddof=1) - lam) < Z_MAX * var_se
