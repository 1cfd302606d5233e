"""Photometric period or rotation period: does the light curve repeat after P or after 2P?

A body that looks alike after half a turn (a box-wing spinning about its antenna axis, a
cylinder tumbling end over end) repeats its light curve twice per turn: the periodogram's
best period is then half the rotation period. The decision compares the light curve folded
at P and at 2P through a nested-model F-test (Press et al., Numerical Recipes, 14.2; the
"halves of the 2P fold differ" test):

* the *full* model has the harmonics ``1..2K`` of ``1/(2P)`` in each band, the *reduced*
  model only its even ones ``2, 4, ..., 2K`` (the harmonics ``1..K`` of ``1/P``, a curve
  that repeats after P); both also have a cubic polynomial in time per band, so that a slow
  trend left by the detrending is not taken for a difference of the halves;
* ``F = ((chi2_r - chi2_f) / (p_f - p_r)) / (chi2_f / (n - p_f))`` is F-distributed with
  ``(p_f - p_r, n - p_f)`` degrees of freedom when the two halves of the 2P fold are the same
  curve; its residual variance is estimated from the data, so mis-stated sigmas or a light
  curve that changes over the pass make the test more cautious, not less;
* the halves differ when the p-value is below ``alpha`` (0.001);
* a fold period is tested only when it fits at least 3 times into the span (with fewer
  cycles the odd harmonics of the long period fit the slow change of the light curve over
  the pass, not a difference of the halves).

:func:`rotation_period` first halves P while the halves of the P fold do not differ (the best
peak was a multiple of the photometric period), then doubles it when the halves of the 2P
fold differ. When they do not (a body whose halves look alike within the noise), the data
cannot tell, and ``if_symmetric`` says what to assume: ``"double"``, the body looks alike
after half a turn (a box-wing with two like wings spinning about its antenna axis): P is
doubled; ``"keep"``: P is kept; ``"auto"`` (the default): a light curve with one maximum per
photometric cycle is taken as half a turn and P is doubled (maxima: the brightness maxima of
the fitted K-harmonic curve, averaged over the bands with weights ``sum 1/dy^2``, whose
prominence is at least a quarter of the curve's peak-to-peak range), the convention of
asteroid photometry that a rotating body shows two maxima per turn (Harris et al. 1984,
Icarus 57, 251, doi:10.1016/0019-1035(84)90140-1); a light curve that already shows two
maxima per cycle is kept.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from speclight.estimate.period.periodogram import (
    TREND_DEGREE,
    BandSeries,
    design_matrix,
    harmonic_chi2,
)

#: p-value below which the two halves of a fold differ.
ALPHA = 1e-3
#: Fewest cycles of a fold period in the span for its halves to be tested: with fewer, the
#: odd harmonics of the long period fit the slow change of the light curve over the pass.
MIN_CYCLES = 3.0
IfSymmetric = Literal["auto", "double", "keep"]


@dataclass
class HalvesTest:
    """F-test of the two halves of the fold at ``period_s`` (module docstring)."""

    period_s: float
    f_statistic: float
    p_value: float
    differ: bool


def halves_test(series: BandSeries, period_s: float, harmonics: int) -> HalvesTest:
    """Do the two halves of the light curve folded at ``period_s`` differ? (F-test)."""
    from scipy.stats import f as f_dist

    freq = 1.0 / period_s
    full, p_full, _ = harmonic_chi2(
        series, freq, list(range(1, 2 * harmonics + 1)), trend_degree=TREND_DEGREE
    )
    reduced, p_red, _ = harmonic_chi2(
        series, freq, list(range(2, 2 * harmonics + 1, 2)), trend_degree=TREND_DEGREE
    )
    d1, d2 = p_full - p_red, series.t_s.size - p_full
    if d2 <= 0 or full <= 0:
        return HalvesTest(period_s, float("nan"), float("nan"), False)
    stat = max((reduced - full) / d1, 0.0) / (full / d2)
    p = float(f_dist.sf(stat, d1, d2))
    return HalvesTest(period_s, float(stat), p, p < ALPHA)


#: Prominence of a maximum, as a fraction of the folded curve's peak-to-peak range.
PROMINENCE = 0.25


def maxima_per_cycle(series: BandSeries, period_s: float, harmonics: int) -> int:
    """Brightness maxima per cycle of the fitted curve folded at ``period_s`` (module doc);
    the series holds magnitudes, so maxima of brightness are minima of the curve."""
    from scipy.signal import find_peaks

    orders = list(range(1, harmonics + 1))
    _, _, coefs = harmonic_chi2(series, 1.0 / period_s, orders)
    phase = np.linspace(0.0, 3.0, 3 * 360, endpoint=False)
    x = design_matrix(phase * period_s, 1.0 / period_s, orders)
    curve = np.zeros(phase.size)
    wsum = 0.0
    for b, beta in enumerate(coefs):
        w = float(np.sum(1.0 / series.dy[series.band == b] ** 2))
        curve += w * (x @ beta)
        wsum += w
    curve /= wsum
    span = float(np.ptp(curve))
    if span <= 0:
        return 0
    peaks, _ = find_peaks(-curve, prominence=PROMINENCE * span)
    return int(np.sum((phase[peaks] >= 1.0) & (phase[peaks] < 2.0)))


@dataclass
class RotationDecision:
    """The rotation period chosen from the photometric one, and why."""

    photometric_period_s: float
    rotation_period_s: float
    factor: float
    decision: str
    tests: list[HalvesTest]


def rotation_period(
    series: BandSeries,
    period_s: float,
    harmonics: int,
    min_period_s: float,
    if_symmetric: IfSymmetric = "auto",
) -> RotationDecision:
    """Decide between the photometric and the rotation period (module docstring).

    Parameters
    ----------
    series
        The light curves.
    period_s
        The photometric period (the periodogram's best) [s].
    harmonics
        Harmonics of the model folded at ``period_s`` and ``2 period_s``.
    min_period_s
        Shortest period searched [s].
    if_symmetric
        ``auto``, ``double`` or ``keep``: the rotation period when the halves of the 2P fold
        agree.
    """
    tests: list[HalvesTest] = []
    p_ph, factor = period_s, 1.0
    for _ in range(2):  # the best peak may be a multiple of the photometric period
        if p_ph / 2 < min_period_s:
            break
        test = halves_test(series, p_ph, harmonics)
        tests.append(test)
        if test.differ:
            break
        p_ph, factor = p_ph / 2, factor / 2
    if series.span_s < MIN_CYCLES * 2 * p_ph:
        text = (
            f"2P = {2 * p_ph:.6g} s fits fewer than {MIN_CYCLES:g} times into the span "
            f"({series.span_s:.6g} s): the halves of the 2P fold are not tested and the "
            "rotation period is taken as the photometric period"
        )
        return RotationDecision(p_ph, p_ph, factor, text, tests)
    double = halves_test(series, 2 * p_ph, harmonics)
    tests.append(double)
    if double.differ:
        text = (
            f"the two halves of the light curve folded at 2P = {2 * p_ph:.6g} s differ "
            f"(F = {double.f_statistic:.3g}, p = {double.p_value:.2g} < {ALPHA:g}): "
            "the rotation period is twice the photometric period"
        )
        return RotationDecision(p_ph, 2 * p_ph, 2 * factor, text, tests)
    same = (
        f"the halves of the 2P fold agree within the noise (F = {double.f_statistic:.3g}, "
        f"p = {double.p_value:.2g} >= {ALPHA:g})"
    )
    if if_symmetric == "double":
        text = (
            f"{same}; the body is said to look alike after half a turn (--if-symmetric "
            "double): the rotation period is 2P"
        )
        return RotationDecision(p_ph, 2 * p_ph, 2 * factor, text, tests)
    maxima = maxima_per_cycle(series, p_ph, harmonics)
    if if_symmetric == "auto" and maxima <= 1:
        text = (
            f"{same}; the light curve shows one maximum per photometric cycle: taken as "
            "half a turn of a body "
            "that looks alike after half a turn (two maxima per turn), so the rotation "
            "period is 2P (--if-symmetric keep keeps P)"
        )
        return RotationDecision(p_ph, 2 * p_ph, 2 * factor, text, tests)
    why = (
        f"the light curve already shows {maxima} maxima per cycle"
        if maxima > 1
        else "--if-symmetric keep"
    )
    text = f"{same}; {why}: the rotation period is the photometric period"
    return RotationDecision(p_ph, p_ph, factor, text, tests)
