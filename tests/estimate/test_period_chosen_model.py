"""The outlier test and the synodic fit use the model the refinement chooses (issue 25).

References: light curves built with a known period, harmonics, trend and amplitude change;
a cosmic ray added at a known epoch; for the synodic fit, a light curve whose rotation phase
is ``2 pi t / P_sid - phi(t)`` by construction (the differential synodic-sidereal relation,
Harris et al. 1984), so the fit in the bisector's frame must return ``P_sid``.
"""

from __future__ import annotations

import numpy as np

from speclight.estimate.period.outliers import find_outliers
from speclight.estimate.period.peak_refinement import refine_with_model
from speclight.estimate.period.periodogram import BandSeries
from speclight.estimate.period.synodic import sidereal_period


def _series(t: np.ndarray, curves: list[np.ndarray], sigmas: tuple[float, ...]) -> BandSeries:
    n = t.size
    return BandSeries(
        np.tile(t, len(curves)), np.concatenate(curves),
        np.concatenate([np.full(n, s) for s in sigmas]),
        np.repeat(np.arange(len(curves), dtype=np.int64), n), len(curves),
    )  # fmt: skip


def test_a_cosmic_ray_on_a_light_curve_with_many_harmonics_is_found() -> None:
    rng = np.random.default_rng(3)
    t = np.arange(400.0)
    u = 2 * t / t[-1] - 1
    x = 2 * np.pi * t / 23.7
    curve = sum(a * np.cos(k * x + k) for k, a in enumerate((0.3, 0.2, 0.15, 0.1, 0.05), 1))
    sigmas = (0.01, 0.015, 0.02)
    ys = [0.3 * u**2 + (1 + 0.1 * u) * curve + rng.normal(0, s, t.size) for s in sigmas]
    ys[1][200] += 10 * sigmas[1]  # a 10-sigma ray in band 1
    series = _series(t, ys, sigmas)
    peak = refine_with_model(series, 1 / 23.7, 2)
    assert max(peak.orders) >= 5  # the model has the light curve's harmonics
    found = find_outliers(
        series, peak.frequency_hz, peak.orders, peak.trend_degree, peak.amplitude_change
    )
    assert list(found.index) == [400 + 200]


def test_the_bisector_frame_fit_recovers_the_sidereal_period() -> None:
    rng = np.random.default_rng(4)
    p_sid = 37.0
    t = np.arange(600.0)
    phi = 1.2 * np.arctan((t - 300) / 60)  # the bisector's azimuth about the spin axis
    pab = np.stack([np.cos(phi), np.sin(phi), np.full_like(t, 0.3)], axis=1)
    x = 2 * np.pi * t / p_sid - phi
    u = 2 * t / t[-1] - 1
    curve = 0.3 * np.cos(x) + 0.15 * np.cos(2 * x + 1) + 0.08 * np.cos(3 * x + 2)
    sigmas = (0.01, 0.02)
    ys = [0.4 * u**2 + (1 + 0.15 * u) * curve + rng.normal(0, s, t.size) for s in sigmas]
    series = _series(t, ys, sigmas)
    rate = float(np.mean(np.gradient(phi, t)))
    p_syn = 1 / (1 / p_sid - rate / (2 * np.pi))
    axis = np.array([0.0, 0.0, 1.0])
    fit = sidereal_period(series, p_syn, 2, t, pab, np.ones(t.size), axis)
    assert fit.sidereal_period_s is not None and fit.sidereal_std_s is not None
    # within 4 of its (calibrated, bench/bench_period_synodic_model.py) sigma
    assert abs(fit.sidereal_period_s - p_sid) < 4 * fit.sidereal_std_s
    assert fit.sidereal_std_s < 0.01 * abs(p_syn - p_sid)  # far below the correction
