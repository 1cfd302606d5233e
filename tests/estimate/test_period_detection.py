"""Detection and robustness of ``speclight period`` (issue 25): the analytic false-alarm
probability against astropy's and against the permutation bootstrap, no period on a light
curve that only drifts, outliers left out, a tumbler's two frequencies, unsorted rows."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from astropy.timeseries import LombScargle

from speclight.estimate.period.analytic_fap import analytic_fap
from speclight.estimate.period.period_run import estimate_period
from speclight.estimate.period.periodogram import BandSeries, multiband_power


def _series(t, y, dy, n_bands):
    n = t.size
    return BandSeries(
        np.tile(t, n_bands), y.ravel(), np.broadcast_to(dy, y.shape).ravel().astype(float),
        np.repeat(np.arange(n_bands), n).astype(np.int64), n_bands,
    )  # fmt: skip


def test_one_band_one_harmonic_is_astropys_baluev():
    # Baluev (2008) eq. 6 as astropy computes it (false_alarm_probability(method="baluev"));
    # our band starts at 1e-6 Hz where astropy's starts at 0: relative 4e-6 of W.
    rng = np.random.default_rng(1)
    t = np.sort(rng.uniform(0, 500, 300))
    dy = rng.uniform(0.5, 1.5, 300)
    y = rng.normal(0, dy)
    ls = LombScargle(t, y, dy)
    # astropy's band ends at the last point of its own grid: use that grid
    freq = ls.autofrequency(minimum_frequency=1e-6, maximum_frequency=0.3)
    fap = analytic_fap(_series(t, y[None], dy[None], 1), freq, 1, 0.1)
    fap.noise_level = 1.0
    for z in (0.04, 0.06, 0.1):
        ref = ls.false_alarm_probability(
            z, method="baluev", minimum_frequency=1e-6, maximum_frequency=0.3
        )
        assert fap.fap(z) == pytest.approx(ref, rel=1e-4)


@pytest.mark.parametrize(("n_bands", "harmonics"), [(2, 1), (1, 2), (2, 2)])
def test_multiband_multiharmonic_fap_bounds_the_permutation_bootstrap(n_bands, harmonics):
    # The maximum of the multi-band statistic over 2000 permutations of white noise
    # (Suveges 2014's bootstrap; computed here with orthonormal bases per frequency, checked
    # against multiband_power): the analytic value is the Rice/Davies upper bound of the
    # continuous maximum (Baluev 2008), so the grid's empirical exceedance lies below it
    # (4 binomial standard errors) and not far below (the grid samples each peak 5 times;
    # measured 0.3-0.9 of the bound at FAP 0.01-0.3).
    rng = np.random.default_rng(5)
    n, draws = 150, 2000
    t = np.sort(rng.uniform(0, 300, n))
    freq = np.linspace(1 / 100, 1 / 4, int((1 / 4 - 1 / 100) * 5 * 300) + 1)
    bases = []
    for f in freq:
        x = np.concatenate(
            [np.stack([np.cos(2 * np.pi * k * f * t), np.sin(2 * np.pi * k * f * t)], 1)
             for k in range(1, harmonics + 1)], axis=1,
        )  # fmt: skip
        bases.append(np.linalg.qr(x - x.mean(0))[0])
    q = np.stack(bases)
    y0 = rng.normal(size=(n_bands, n))
    s = _series(t, y0, np.ones((n_bands, n)), n_bands)
    direct = sum(np.sum(np.einsum("fnk,n->fk", q, y - y.mean()) ** 2, 1) for y in y0)
    np.testing.assert_allclose(
        direct / np.sum((y0 - y0.mean(1, keepdims=True)) ** 2),
        multiband_power(s, freq, harmonics), atol=1e-10,
    )  # fmt: skip
    perm = np.stack([np.stack([rng.permutation(y) for _ in range(draws)], 1) for y in y0])
    num = sum(np.sum(np.einsum("fnk,nd->fkd", q, yb) ** 2, axis=1) for yb in perm)
    den = sum(np.sum((yb - yb.mean(0)) ** 2, axis=0) for yb in perm)
    zmax = (num / den).max(axis=0)
    fap = analytic_fap(s, freq, harmonics, 0.1)
    fap.noise_level = 1.0
    for level in (0.3, 0.1, 0.03):
        emp = float(np.mean(zmax >= fap.power_at(level)))
        se = np.sqrt(level * (1 - level) / draws)
        assert emp <= level + 4 * se
        assert emp >= 0.25 * level - 4 * se


def _csv(path: Path, t_s, rate, sigma, names=("B", "G", "R")) -> Path:
    start = np.datetime64("2020-02-29T21:13:00", "ms")
    lines = ["time," + ",".join(names) + "," + ",".join(f"{b}_sigma" for b in names)]
    for i, t in enumerate(t_s):
        stamp = str(start + np.timedelta64(round(t * 1000), "ms")) + "Z"
        lines.append(
            ",".join([stamp, *(f"{v:.6g}" for v in rate[i]), *(f"{v:.6g}" for v in sigma[i])])
        )
    path.write_text("\n".join(lines) + "\n")
    return path


def _rates(mag, snr):
    rate = 1e4 * 10 ** (-0.4 * mag)
    return rate, rate / snr


def test_a_light_curve_that_only_drifts_has_no_period_and_a_lower_bound(tmp_path):
    # A non-rotating sphere's pass: a smooth brightening (range, phase angle) with a bump
    # no cubic removes (the penumbra exit), SNR 50, 3 bands: no period at FAP < 0.01.
    rng = np.random.default_rng(7)
    t = np.arange(0.0, 480.0, 1.0)
    x = t / t[-1]
    mag = 1.5 * x**2 - 2.0 * x + 0.6 * np.exp(-(((x - 0.15) / 0.08) ** 2)) + 0.3 * np.sin(5 * x)
    rate, sigma = _rates(mag[:, None] + np.array([0.0, 0.1, 0.2]), 50.0)
    rate = rate + rng.normal(0, sigma)
    out = estimate_period(_csv(tmp_path / "d.csv", t, rate, sigma)).to_json()
    assert out["detected"] is False and out["false_alarm_probability"] >= 0.01
    assert out["period_s"] is None and out["period_lower_bound_s"] == pytest.approx(t[-1] / 3)


def _spinning(t, period_s, snr, rng):
    ph = 2 * np.pi * t / period_s
    mag = 0.3 * np.cos(ph) + 0.15 * np.cos(2 * ph + 0.7) + 0.2 * np.cos(3 * ph + 1.1)
    rate, sigma = _rates(mag[:, None] + np.array([0.0, 0.1, 0.2]), snr)
    return rate + rng.normal(0, sigma), sigma


def test_a_cosmic_ray_is_left_out_and_the_period_stays(tmp_path):
    # One +100 sigma point in one band of a 7.3 s light curve: left out and reported, the
    # period unchanged within 0.05 s (issue 25).
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 300.0, 1.0)
    rate, sigma = _spinning(t, 7.3, 30.0, rng)
    clean = estimate_period(_csv(tmp_path / "c.csv", t, rate, sigma)).to_json()
    rate[150, 1] += 100 * sigma[150, 1]
    hit = estimate_period(_csv(tmp_path / "h.csv", t, rate, sigma)).to_json()
    assert [(o["band"], o["time_s"]) for o in hit["outliers"]] == [("G", 150.0)]
    assert clean["outliers"] == []
    assert abs(hit["period_s"] - clean["period_s"]) < 0.05


def test_a_tumbler_shows_two_frequencies_and_a_spinner_one(tmp_path):
    # Pravec et al. (2005) eq. 1: a 2-D Fourier series in f1 = 1/28.25 Hz and
    # f2 = 1/85.8 Hz (the torque-free tumbler) with mixed terms j f1 + k f2.
    rng = np.random.default_rng(11)
    t = np.arange(0.0, 600.0, 1.0)
    f1, f2 = 1 / 28.25, 1 / 85.8
    terms = [(1, 0, 0.3), (2, 0, 0.15), (0, 1, 0.12), (1, 1, 0.12), (1, -1, 0.1), (2, -1, 0.08)]
    mag = sum(a * np.cos(2 * np.pi * (j * f1 + k * f2) * t + j + k) for j, k, a in terms)
    rate, sigma = _rates(mag[:, None] + np.array([0.0, 0.1, 0.2]), 50.0)
    rate = rate + rng.normal(0, sigma)
    out = estimate_period(_csv(tmp_path / "t.csv", t, rate, sigma), if_symmetric="keep").to_json()
    tumbling = out["tumbling"]
    assert tumbling["detected"] and out["verdict"].startswith("tumbling")
    found = sorted(tumbling["periods_s"])
    # within 5 Cramer-Rao standard deviations of a sinusoid's frequency in white noise,
    # sqrt(6/N) sigma / (pi A T) (Kovacs 1981), N = 1800 points, sigma = 0.0217 mag, the
    # fundamentals' amplitudes A = 0.3 and 0.12 mag, T = 600 s; times P^2
    for p, a, got in ((28.25, 0.3, found[0]), (85.8, 0.12, found[1])):
        std_f = np.sqrt(6 / 1800) * 0.0217 / (np.pi * a * 600)
        assert got == pytest.approx(p, abs=5 * std_f * p**2)
    rate, sigma = _spinning(t, 28.25, 50.0, rng)
    one = estimate_period(_csv(tmp_path / "s.csv", t, rate, sigma)).to_json()
    assert not one["tumbling"]["detected"]


def test_unsorted_rows_are_sorted_with_a_notice(tmp_path):
    rng = np.random.default_rng(2)
    t = np.arange(0.0, 200.0, 1.0)
    rate, sigma = _spinning(t, 13.0, 30.0, rng)
    order = rng.permutation(t.size)
    with warnings.catch_warnings(record=True):
        warnings.simplefilter("always")
        mixed = estimate_period(_csv(tmp_path / "m.csv", t[order], rate[order], sigma[order]))
    ordered = estimate_period(_csv(tmp_path / "o.csv", t, rate, sigma))
    assert "sorted by time" in mixed.to_json()["notices"][0]
    assert mixed.period_s == pytest.approx(ordered.period_s, rel=1e-12)


@pytest.mark.parametrize(
    ("shoulder", "expected"),
    [(0.0, 1), (0.3, 1), (1.0, 2)],  # second maximum's height relative to the first
)
def test_principal_maxima_per_cycle(shoulder, expected):
    # A brightness curve (magnitudes: maxima are minima) with one maximum at phase 0 and a
    # second of relative height `shoulder` at phase 0.5: exactly representable by K = 4
    # harmonics (cos^2 terms), so the fit is the curve itself.
    from speclight.estimate.period.period_decision import maxima_per_cycle

    period = 10.0
    t = np.linspace(0.0, 200.0, 2001)
    phase = 2 * np.pi * t / period
    y = -(np.cos(phase / 2) ** 8) - shoulder * np.sin(phase / 2) ** 8
    series = _series(t, y[None], np.full(t.size, 0.01), 1)
    assert maxima_per_cycle(series, period, 4) == expected


def test_auto_reports_2p_for_one_maximum_and_p_for_two():
    # Halves of the 2P fold alike (a curve exactly periodic in P): "P or 2P" either way;
    # one principal maximum per P -> 2P (half a turn), two unequal principal maxima (heights
    # 1 and 0.8: P cannot be halved) -> P (Harris 1984).
    from speclight.estimate.period.period_decision import rotation_period

    period = 10.0
    t = np.linspace(0.0, 300.0, 3001)
    phase = 2 * np.pi * t / period
    rng = np.random.default_rng(3)
    for y, expected in (
        (-(np.cos(phase / 2) ** 8), 2 * period),
        (-(np.cos(phase / 2) ** 8) - 0.8 * np.sin(phase / 2) ** 8, period),
    ):
        y = y + rng.normal(0.0, 0.01, t.size)
        series = _series(t, y[None], np.full(t.size, 0.01), 1)
        decision = rotation_period(series, period, 4, 1.0, "auto")
        assert decision.ambiguous
        assert decision.rotation_period_s == pytest.approx(expected, rel=1e-12)
