"""Outliers of a light curve: single points far off the fitted curve in one band (a cosmic
ray, a satellite streak), found and left out before the period is decided.

The model the refinement chose at the best frequency (harmonics, trend degree per band,
amplitude change: :func:`.peak_refinement.refine_with_model`) is fitted; each point's
residual is divided by its sigma and by the band's robust scale (1.4826 times the median
absolute deviation of those residuals: the standard deviation of Gaussian residuals, blind to
a few outliers; Rousseeuw & Croux 1993, JASA 88, 1273). A point is an outlier when its
scaled residual exceeds Chauvenet's limit for ``N`` points at 1 % (``|r| > z`` with
``N P(|Z| > z) = 0.01``: one false rejection in a hundred light curves of pure Gaussian
noise; Taylor, An Introduction to Error Analysis, 1997, ch. 6) and it stands alone: the other
bands at the same epoch (or, for a single band, its neighbours in time) stay within half that
limit. A glint lights every band at once and lasts for several epochs: it is kept.
``speclight period`` looks twice (:func:`combined`): about the periodogram's harmonics and a
cubic, then, without what that found, about the model the refinement chooses. The first
alone leaves a light curve's further harmonics and trend in the residuals, which widen the
robust scale (on a 5-harmonic light curve in 3 bands an 8-sigma cosmic ray was found in 0
of 15 noise draws, against 14 of 15 with the chosen model:
bench/bench_period_outlier_model.py); the second alone lets a far-off point drive the
model's choice (a +100-sigma ray took a trend of degree 20, whose bend beside it then
looked like outliers too).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.period.periodogram import (
    TREND_DEGREE,
    BandSeries,
    harmonic_chi2,
    residual_lag1_correlation,
)

#: Expected number of Gaussian points wrongly rejected per light curve (Chauvenet's rule).
FALSE_REJECTIONS = 0.01
#: Scale of the median absolute deviation to a Gaussian standard deviation.
MAD_TO_SIGMA = 1.4826


@dataclass
class Outliers:
    """Points left out: their indices in the series, times [s], bands and scaled residuals."""

    index: NDArray[np.int64]
    t_s: NDArray[np.float64]
    band: NDArray[np.int64]
    residual_sigma: NDArray[np.float64]
    limit_sigma: float


def find_outliers(
    series: BandSeries, frequency_hz: float, orders: list[int],
    trend_degree: int = TREND_DEGREE, amplitude_change: bool = False,
) -> Outliers:  # fmt: skip
    """The outliers of ``series`` about its fit at ``frequency_hz`` (module docstring).

    Parameters
    ----------
    series
        The detrended light curves.
    frequency_hz
        The best frequency [Hz].
    orders
        The harmonics fitted.
    trend_degree
        Degree of the polynomial trend per band.
    amplitude_change
        Whether the harmonics' amplitude changes linearly over the pass
        (:func:`.periodogram.band_design`).
    """
    from scipy.stats import norm

    model = (trend_degree, amplitude_change)
    _, _, coefs = harmonic_chi2(series, frequency_hz, orders, None, *model)
    _, res = residual_lag1_correlation(series, frequency_hz, orders, coefs, None, *model)
    r = np.zeros_like(res)
    for b in range(series.n_bands):
        m = series.band == b
        if m.sum() < 3:
            continue
        mad = float(np.median(np.abs(res[m] - np.median(res[m]))))
        r[m] = res[m] / max(MAD_TO_SIGMA * mad, 1e-300)
    limit = float(norm.isf(FALSE_REJECTIONS / (2 * max(r.size, 1))))
    high = np.abs(r) > limit
    alone = np.zeros(r.size, dtype=bool)
    for i in np.flatnonzero(high):
        same = np.flatnonzero((series.t_s == series.t_s[i]) & (np.arange(r.size) != i))
        if same.size:
            alone[i] = bool(np.all(np.abs(r[same]) < limit / 2))
            continue
        own = np.flatnonzero(series.band == series.band[i])
        k = int(np.searchsorted(series.t_s[own], series.t_s[i]))
        near = own[[j for j in (k - 1, k + 1) if 0 <= j < own.size]]
        alone[i] = bool(np.all(np.abs(r[near]) < limit / 2))
    idx = np.flatnonzero(alone).astype(np.int64)
    return Outliers(idx, series.t_s[idx], series.band[idx], r[idx], limit)


def without(series: BandSeries, index: NDArray[np.int64]) -> BandSeries:
    """``series`` without the points ``index``."""
    keep = np.ones(series.t_s.size, dtype=bool)
    keep[index] = False
    return BandSeries(
        series.t_s[keep], series.y[keep], series.dy[keep], series.band[keep], series.n_bands
    )


def combined(first: Outliers, second: Outliers, n_points: int) -> Outliers:
    """The outliers ``first`` of a series of ``n_points`` and ``second`` of that series
    without them, as outliers of the whole series."""
    kept = np.delete(np.arange(n_points, dtype=np.int64), first.index)
    index = np.concatenate([first.index, kept[second.index]]).astype(np.int64)
    return Outliers(
        index,
        np.concatenate([first.t_s, second.t_s]),
        np.concatenate([first.band, second.band]).astype(np.int64),
        np.concatenate([first.residual_sigma, second.residual_sigma]),
        max(first.limit_sigma, second.limit_sigma),
    )
