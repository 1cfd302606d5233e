"""The period core on synthetic light curves: recovery of known periods, the P/2P decision,
the bootstrap false-alarm probability against astropy's, the synodic correction."""

from __future__ import annotations

import numpy as np
import pytest

from speclight.estimate.period.peak_refinement import refine_peak, refine_with_model
from speclight.estimate.period.period_decision import rotation_period
from speclight.estimate.period.period_fap import bootstrap_maxima
from speclight.estimate.period.periodogram import (
    BandSeries,
    frequency_grid,
    harmonic_chi2,
    local_maxima,
    multiband_power,
)
from speclight.estimate.period.synodic import sidereal_period


def _series(t_s, values, sigma):
    """BandSeries of (N, B) values with one sigma for all."""
    n, nb = values.shape
    return BandSeries(
        t_s=np.repeat(t_s, nb),
        y=values.ravel(),
        dy=np.full(n * nb, sigma),
        band=np.tile(np.arange(nb), n).astype(np.int64),
        n_bands=nb,
    )


def _best(series, harmonics, min_p, max_p):
    freq = frequency_grid(series.span_s, min_p, max_p)
    power = multiband_power(series, freq, harmonics)
    k = int(local_maxima(power, 1)[0])
    return refine_peak(series, float(freq[k]), list(range(1, harmonics + 1))), freq, power


def test_multiband_power_is_the_chi2_fraction_of_the_joint_harmonic_fit():
    # astropy's per-band LombScargle powers, chi2_0-weighted, against a direct numpy least
    # squares fit of the same model (1 - sum chi2 / sum chi2_0, VanderPlas & Ivezic 2015).
    rng = np.random.default_rng(3)
    t = np.sort(rng.uniform(0, 300, 150))
    y = np.stack([np.cos(2 * np.pi * t / 41.0) * a for a in (0.3, 0.5)], 1)
    s = _series(t, y + rng.normal(0, 0.1, y.shape), 0.1)
    freq = np.array([1 / 60.0, 1 / 41.0, 1 / 17.0])
    power = multiband_power(s, freq, 2)
    chi0 = sum(np.sum((s.y[s.band == b] - s.y[s.band == b].mean()) ** 2) / 0.1**2 for b in range(2))
    direct = [1 - harmonic_chi2(s, f, [1, 2])[0] / chi0 for f in freq]
    np.testing.assert_allclose(power, direct, rtol=1e-8, atol=1e-10)


def test_recovers_a_multiband_harmonic_signal_within_its_standard_deviation():
    # Three bands, a rotation-like curve (fundamental + 2nd and 3rd harmonics, different
    # amplitudes per band) at P = 37 s, Gaussian noise 0.05 mag, 400 random epochs in 400 s.
    rng = np.random.default_rng(11)
    period = 37.0
    t = np.sort(rng.uniform(0, 400, 400))
    x = 2 * np.pi * t / period
    shape = 0.4 * np.cos(x) + 0.25 * np.sin(2 * x + 0.3) + 0.1 * np.cos(3 * x - 1.0)
    y = np.stack([a * shape for a in (1.0, 0.8, 1.2)], 1)
    s = _series(t, y + rng.normal(0, 0.05, y.shape), 0.05)
    peak, _, _ = _best(s, 3, 4.0, 200.0)
    # the periodogram's resolution is 1/span = 2.5e-3 Hz; the fit's std is far below it
    assert peak.frequency_std_hz < 0.05 / s.span_s
    assert abs(peak.frequency_hz - 1 / period) < 4 * peak.frequency_std_hz


def test_frequency_std_matches_the_cramer_rao_bound_of_a_sinusoid():
    # One band, one sinusoid of amplitude A in white noise sigma, N even epochs over T:
    # sigma_f = sqrt(6 / N) sigma / (pi A T) (Kovacs 1981, Ap&SS 78, 175; Montgomery &
    # O'Donoghue 1999, DSSN 13, 28). The fitted std must agree to the noise of its own
    # estimate (the reduced chi2 from N - 3 degrees of freedom: ~ 1/sqrt(2N) = 3 %).
    rng = np.random.default_rng(5)
    n, span, amp, sigma = 1000, 500.0, 0.2, 0.05
    t = np.linspace(0, span, n)
    y = amp * np.cos(2 * np.pi * t / 23.0 + 0.4) + rng.normal(0, sigma, n)
    s = _series(t, y[:, None], sigma)
    peak = refine_peak(s, 1 / 23.0, [1])
    expected = np.sqrt(6 / n) * sigma / (np.pi * amp * span)
    assert peak.frequency_std_hz == pytest.approx(expected, rel=0.1)
    assert abs(peak.frequency_hz - 1 / 23.0) < 4 * expected


def test_refined_model_gives_the_cramer_rao_bound_with_harmonics_and_a_bump():
    # Four harmonics A_k = 0.3/k and a slow change no cubic removes (a Gaussian bump of 0.5
    # mag, a tenth of the pass wide) in white noise sigma: the bound of the test above summed
    # over the harmonics' information, sigma_f = sqrt(6 / N) sigma / (pi T sqrt(sum k^2
    # A_k^2)) (Kay 1993, Fundamentals of Statistical Signal Processing I, ch. 3: the Fisher
    # information of independent harmonics adds). The periodogram's K = 2 harmonics and cubic
    # leave the higher harmonics and the bump in the residuals (reduced chi2 in the hundreds):
    # their std is many times the bound. The model the light curve needs must reach the
    # bound to the noise of its own estimate (~3 %) plus the trend's few columns' coupling.
    rng = np.random.default_rng(11)
    n, span, period, sigma = 1000, 600.0, 23.0, 0.01
    t = np.linspace(0, span, n)
    amp = 0.3 / np.arange(1, 5)
    x = 2 * np.pi * t / period
    y = sum(a * np.cos(k * x + rng.uniform(0, 2 * np.pi)) for k, a in enumerate(amp, 1))
    y = y + 0.5 * np.exp(-(((t / span - 0.4) / 0.1) ** 2)) + 0.2 * (t / span) ** 3
    s = _series(t, (y + rng.normal(0, sigma, n))[:, None], sigma)
    bound = np.sqrt(6 / n) * sigma / (np.pi * span * np.sqrt(np.sum((np.arange(1, 5) * amp) ** 2)))
    start = 1 / period + 0.07 / span  # within the periodogram grid's step 1/(5 span)
    plain = refine_peak(s, start, [1, 2])
    assert plain.frequency_std_hz > 5 * bound  # the misfit the test is about
    peak = refine_with_model(s, start, 2)
    assert peak.orders == [1, 2, 3, 4] and peak.trend_degree > 3
    assert peak.frequency_std_hz == pytest.approx(bound, rel=0.15)
    assert abs(peak.frequency_hz - 1 / period) < 4 * bound


def test_refined_model_gives_the_bound_when_the_amplitude_changes_over_the_pass():
    # Amplitude growing by +-20 % over the pass, A(t) = A (1 + c u), u = -1..1: the Fisher
    # information of the frequency, sum (2 pi k t)^2 A_k(t)^2 / 2 sigma^2 with t about
    # mid-pass, grows by (2/3 + 2 c^2/5) / (2/3) = 1 + 3 c^2 / 5 over the constant-amplitude
    # bound above. The change is deterministic and orthogonal to a frequency shift: a model
    # without it counts it as noise (reduced chi2 ~ 3, std ~ 2x); the amplitude-change
    # column must bring the std to the bound within the 15 % of the test above.
    rng = np.random.default_rng(12)
    n, span, period, sigma, c = 1000, 600.0, 23.0, 0.005, 0.2
    t = np.linspace(0, span, n)
    u = 2 * t / span - 1
    x = 2 * np.pi * t / period
    y = (1 + c * u) * (0.3 * np.cos(x + 0.4) + 0.1 * np.cos(2 * x - 1.0))
    s = _series(t, (y + rng.normal(0, sigma, n))[:, None], sigma)
    info = (0.3**2 + (2 * 0.1) ** 2) * (1 + 3 * c**2 / 5)
    bound = np.sqrt(6 / n) * sigma / (np.pi * span * np.sqrt(info))
    start = 1 / period - 0.06 / span
    assert refine_peak(s, start, [1, 2]).frequency_std_hz > 1.5 * bound
    peak = refine_with_model(s, start, 2)
    assert peak.amplitude_change
    assert peak.frequency_std_hz == pytest.approx(bound, rel=0.15)
    assert abs(peak.frequency_hz - 1 / period) < 4 * bound


def _two_fold(odd_amplitude, seed=2):
    # rotation period 100 s over 600 s; a two-fold curve (2nd and 4th harmonics of the
    # rotation: one maximum per half turn) plus an odd (1st) harmonic of the given amplitude
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 600.0, 1.0)
    x = 2 * np.pi * t / 100.0
    shape = 0.5 * np.cos(2 * x) + 0.15 * np.cos(4 * x + 0.5) + odd_amplitude * np.cos(x + 1.0)
    y = np.stack([shape, 0.7 * shape], 1)
    return _series(t, y + rng.normal(0, 0.03, y.shape), 0.03)


def test_symmetric_light_curve_photometric_period_is_half_the_rotation():
    s = _two_fold(0.0)
    peak, _, _ = _best(s, 3, 6.0, 300.0)
    assert 1 / peak.frequency_hz == pytest.approx(50.0, rel=0.01)
    doubled = rotation_period(s, 1 / peak.frequency_hz, 3, 6.0, "double")
    assert not doubled.tests[-1].differ  # the halves of the 100 s fold agree
    assert doubled.rotation_period_s == pytest.approx(100.0, rel=0.01)
    kept = rotation_period(s, 1 / peak.frequency_hz, 3, 6.0, "keep")
    assert kept.rotation_period_s == pytest.approx(50.0, rel=0.01)


def test_asymmetric_halves_give_the_rotation_period_whatever_the_rule():
    # an odd harmonic of 0.05 mag (1.7 sigma per point, 1200 points): the halves differ
    s = _two_fold(0.05)
    peak, _, _ = _best(s, 3, 6.0, 300.0)
    for rule in ("double", "keep"):
        d = rotation_period(s, 1 / peak.frequency_hz, 3, 6.0, rule)  # type: ignore[arg-type]
        assert d.rotation_period_s == pytest.approx(100.0, rel=0.01)
        assert any(t.differ for t in d.tests)


def test_best_peak_at_twice_the_photometric_period_is_halved():
    # a subharmonic handed in (200 s for a curve repeating every 50 s) comes down to 50 s
    s = _two_fold(0.0)
    d = rotation_period(s, 200.0, 3, 6.0, "keep")
    assert d.photometric_period_s == pytest.approx(50.0)


def test_bootstrap_false_alarm_matches_astropy_single_band():
    # The permutation bootstrap against astropy's bootstrap (resampling with replacement,
    # VanderPlas 2018, section 7.4) on the same grid, single band, pure noise: both estimate
    # the probability that noise gives a peak above p0; each has the binomial error
    # sqrt(p (1 - p) / n); they must agree within 4 combined standard errors.
    from astropy.timeseries import LombScargle

    rng = np.random.default_rng(7)
    t = np.sort(rng.uniform(0, 200, 120))
    y = rng.normal(0, 1.0, t.size)
    s = _series(t, y[:, None], 1.0)
    fmin, fmax = 1 / 100.0, 1 / 4.0
    freq = frequency_grid(s.span_s, 4.0, 100.0)
    p_obs = float(multiband_power(s, freq, 1).max())
    n = 300
    mine = bootstrap_maxima(s, freq, 1, draws=n, seed=0)
    frac = float(np.mean(mine.maxima >= p_obs))
    ls = LombScargle(t, y, np.ones_like(t))
    theirs = ls.false_alarm_probability(
        p_obs,
        method="bootstrap",
        minimum_frequency=fmin,
        maximum_frequency=fmax,
        samples_per_peak=5,
        method_kwds={"n_bootstraps": n, "random_seed": 1},
    )
    p = 0.5 * (frac + theirs)
    assert abs(frac - theirs) < 4 * np.sqrt(2 * p * (1 - p) / n)
    # pure noise: its highest peak is no detection
    assert mine.false_alarm_probability(p_obs) > 0.05
    # the Gumbel fit and the counting agree where counting has draws to count
    assert mine.false_alarm_probability(p_obs) == pytest.approx(frac, abs=4 * np.sqrt(p / n))


def test_a_real_signal_has_the_false_alarm_probability_of_baluev():
    # A weak sinusoid: the Gumbel fit's FAP, far below 1/draws, against astropy's Baluev
    # (2008, MNRAS 385, 1279) analytic FAP. The fit's error in ln(FAP) is about
    # z * se(scale)/scale with z = -ln(FAP) and se(scale)/scale = 0.78/sqrt(n) (the Gumbel
    # MLE, Johnson, Kotz & Balakrishnan, Continuous Univariate Distributions 2, ch. 22);
    # they must agree within 3 of those.
    from astropy.timeseries import LombScargle

    rng = np.random.default_rng(8)
    t = np.sort(rng.uniform(0, 200, 120))
    y = 0.8 * np.sin(2 * np.pi * t / 13.0) + rng.normal(0, 1.0, t.size)
    s = _series(t, y[:, None], 1.0)
    freq = frequency_grid(s.span_s, 4.0, 100.0)
    p_obs = float(multiband_power(s, freq, 1).max())
    n = 100
    mine = bootstrap_maxima(s, freq, 1, draws=n, seed=0).false_alarm_probability(p_obs)
    baluev = LombScargle(t, y, np.ones_like(t)).false_alarm_probability(
        p_obs, minimum_frequency=1 / 100.0, maximum_frequency=1 / 4.0, samples_per_peak=5
    )
    assert mine < 1e-3
    z = -np.log(baluev)
    assert abs(np.log(mine) - np.log(baluev)) < 3 * z * 0.78 / np.sqrt(n)


def test_synodic_correction_recovers_the_sidereal_period():
    # A body spinning at P_sid = 60 s about z; the light curve is a function of the body-frame
    # azimuth of the phase-angle bisector, g(2 pi t / P_sid - phi(t)), with the bisector
    # turning non-uniformly (a pass: fast in the middle). The plain periodogram sees the
    # synodic period; the fit in the bisector's frame must give back 60 s.
    rng = np.random.default_rng(4)
    t = np.arange(0.0, 600.0, 1.0)
    phi = -1.5 * (1 + np.tanh((t - 300) / 80)) / 2  # -86 deg over the pass
    pab = np.stack([np.cos(phi), np.sin(phi), np.full_like(phi, 0.4)], 1)
    pab /= np.linalg.norm(pab, axis=1, keepdims=True)
    x = 2 * np.pi * t / 60.0 - phi
    y = np.stack([0.5 * np.cos(x) + 0.2 * np.cos(2 * x + 1)] * 2, 1)
    s = _series(t, y + rng.normal(0, 0.03, y.shape), 0.03)
    peak, _, _ = _best(s, 2, 6.0, 300.0)
    p_syn = 1 / peak.frequency_hz
    weight = np.full(t.size, 2 / 0.03**2)
    corr = sidereal_period(s, p_syn, 1, t, pab, weight, np.array([0.0, 0.0, 1.0]))
    assert corr.applied
    assert abs(corr.sidereal_period_s - 60.0) < 4 * corr.sidereal_std_s
    assert abs(corr.sidereal_period_s - 60.0) < abs(p_syn - 60.0)
    # the linear relation with the mean rate: P_sid = 1/(1/P_syn + Omega/(2 pi)) (Harris et
    # al. 1984), Omega the weighted slope of phi
    slope = np.polyfit(t, phi, 1)[0]
    assert corr.bisector_rate_rad_s == pytest.approx(slope, rel=1e-9)
    # without the axis: only the bound, P^2 |dPAB/dt| / (2 pi)
    bound = sidereal_period(s, p_syn, 1, t, pab, weight, None)
    assert not bound.applied and bound.bound_s > 0


def test_uniform_bisector_drift_shifts_the_peak_by_the_synodic_relation():
    # phi = Omega t exactly: the light curve's frequency is f_sid - Omega / (2 pi) (closed
    # form); the periodogram's peak must sit there within its standard deviation.
    rng = np.random.default_rng(6)
    t = np.arange(0.0, 600.0, 1.0)
    omega = -0.004
    x = 2 * np.pi * t / 60.0 - omega * t
    y = (0.5 * np.cos(x))[:, None]
    s = _series(t, y + rng.normal(0, 0.03, y.shape), 0.03)
    peak, _, _ = _best(s, 1, 6.0, 300.0)
    f_syn = 1 / 60.0 - omega / (2 * np.pi)
    assert abs(peak.frequency_hz - f_syn) < 4 * peak.frequency_std_hz


def test_frequency_std_covers_red_noise_scatter():
    # AR(1) noise (lag-1 correlation 0.9, as the residuals of a pass whose light curve changes
    # slowly): the reported std, inflated for the noise's spectrum at the harmonics, must
    # match the scatter of the estimates over 100 realisations. The scatter of 100 draws is
    # known to 1/sqrt(2 * 100) = 7 %; 3 of those plus the 5-10 % by which the asymptotic
    # bound misses at N = 600 even in white noise (test above) give the 0.3 tolerance.
    rng = np.random.default_rng(2)
    n, rho, sigma = 600, 0.9, 0.05
    t = np.arange(n, dtype=float)
    found, reported = [], []
    for _ in range(100):
        e = np.empty(n)
        e[0] = rng.normal(0, sigma)
        w = rng.normal(0, sigma * np.sqrt(1 - rho**2), n)
        for k in range(1, n):
            e[k] = rho * e[k - 1] + w[k]
        y = 0.2 * np.cos(2 * np.pi * t / 23 + 0.4) + 0.1 * np.cos(4 * np.pi * t / 23) + e
        peak = refine_peak(_series(t, y[:, None], sigma), 1 / 23, [1, 2])
        found.append(peak.frequency_hz)
        reported.append(peak.frequency_std_hz)
    assert np.std(found) / np.mean(reported) == pytest.approx(1.0, abs=0.3)
