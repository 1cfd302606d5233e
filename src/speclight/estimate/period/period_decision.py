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
  curve that changes over the pass make the test more cautious, not less, and residuals
  correlated from epoch to epoch (lag-1 correlation ``rho`` of the full model's) count as
  ``n (1 - rho) / (1 + rho)`` points (:func:`nested_f_test`) in the test that doubles a
  period (not in the one that halves it: each errs towards keeping the period found);
* the halves differ when the p-value is below ``alpha`` (0.001);
* a fold period is tested only when it fits at least 3 times into the span (with fewer
  cycles the odd harmonics of the long period fit the slow change of the light curve over
  the pass, not a difference of the halves).

:func:`rotation_period` first halves P while the halves of the P fold do not differ (the best
peak was a multiple of the photometric period), then doubles it when the halves of the 2P
fold differ. When they do not, the light curve cannot tell a body that turns in P from one
that looks alike after half a turn and turns in 2P (the built-in box-wing spinning about
its antenna axis is such a body: its light curves at rotation phases 0 and 180 deg agree to
1e-15), the decision says "P or 2P" (``ambiguous``) and ``if_symmetric`` says what to
report: ``"double"``: 2P; ``"keep"``: P; ``"auto"`` (the default): the convention of
asteroid photometry that a rotating body shows two maxima per turn (Harris et al. 1984,
Icarus 57, 251, doi:10.1016/0019-1035(84)90140-1): a light curve with one principal maximum
per photometric cycle (:func:`maxima_per_cycle`) is half a turn, 2P is reported; one that
already shows two is a whole turn, P is reported. Either way the ambiguity is stated.
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


def nested_f_test(
    chi_r: float, p_r: int, chi_f: float, p_f: int, n: int, rho: float = 0.0
) -> tuple[float, float]:
    """F statistic and p-value of nested least-squares models (chi-squares ``chi_r``,
    ``chi_f`` with ``p_r < p_f`` parameters, ``n`` points); residuals with lag-1 correlation
    ``rho > 0`` count as ``n (1 - rho) / (1 + rho)`` independent points (the variance of the
    mean of an AR(1) series, Bartlett 1946, J. R. Stat. Soc. Suppl. 8, 27): the statistic
    is divided, and the denominator's degrees of freedom multiplied, by that factor."""
    from scipy.stats import f as f_dist

    d1, d2 = p_f - p_r, n - p_f
    if d1 <= 0 or d2 <= 0 or chi_f <= 0:
        return float("nan"), float("nan")
    shrink = (1 - rho) / (1 + rho) if rho > 0 else 1.0
    stat = max((chi_r - chi_f) / d1, 0.0) / (chi_f / d2) * shrink
    return float(stat), float(f_dist.sf(stat, d1, max(d2 * shrink, 1.0)))


def halves_test(
    series: BandSeries, period_s: float, harmonics: int, correlated: bool = False
) -> HalvesTest:
    """Do the two halves of the light curve folded at ``period_s`` differ? (F-test; with
    ``correlated``, counting the full model's residual correlation, :func:`nested_f_test`:
    harder to call them different, used before doubling a period)."""
    from speclight.estimate.period.periodogram import residual_lag1_correlation

    freq = 1.0 / period_s
    orders = list(range(1, 2 * harmonics + 1))
    full, p_full, coefs = harmonic_chi2(series, freq, orders, trend_degree=TREND_DEGREE)
    reduced, p_red, _ = harmonic_chi2(
        series, freq, list(range(2, 2 * harmonics + 1, 2)), trend_degree=TREND_DEGREE
    )
    rho = 0.0
    if correlated:
        rho, _ = residual_lag1_correlation(series, freq, orders, coefs, trend_degree=TREND_DEGREE)
    stat, p = nested_f_test(reduced, p_red, full, p_full, series.t_s.size, rho)
    return HalvesTest(period_s, stat, p, bool(p < ALPHA))


#: Prominence of a principal maximum, as a fraction of the folded curve's peak-to-peak range:
#: the two maxima per turn of a double-peaked light curve are comparable; a bump of less than
#: half the range is a shoulder of one maximum (a glint beside a face), not the second one.
PROMINENCE = 0.5


def maxima_per_cycle(series: BandSeries, period_s: float, harmonics: int) -> int:
    """Principal brightness maxima per cycle of the fitted curve folded at ``period_s``.

    The K-harmonic curve of each band, averaged with weights ``sum 1/dy^2``; the series
    holds magnitudes, so maxima of brightness are minima of the curve. A maximum counts when
    its prominence is at least :data:`PROMINENCE` of the curve's peak-to-peak range.
    """
    from scipy.signal import find_peaks

    orders = list(range(1, harmonics + 1))
    _, _, coefs = harmonic_chi2(series, 1.0 / period_s, orders)
    phase = np.linspace(0.0, 3.0, 3 * 360, endpoint=False)  # three cycles: no edge effects
    x = design_matrix(phase * period_s, 1.0 / period_s, orders)
    curve = np.zeros(phase.size)
    weight_sum = 0.0
    for b, beta in enumerate(coefs):
        w = float(np.sum(1.0 / series.dy[series.band == b] ** 2))
        curve += w * (x @ beta)
        weight_sum += w
    curve /= weight_sum
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
    #: True where the halves of the 2P fold agree: the rotation period is P or 2P.
    ambiguous: bool = False


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
    double = halves_test(series, 2 * p_ph, harmonics, correlated=True)
    tests.append(double)
    if double.differ:
        text = (
            f"the two halves of the light curve folded at 2P = {2 * p_ph:.6g} s differ "
            f"(F = {double.f_statistic:.3g}, p = {double.p_value:.2g} < {ALPHA:g}): "
            "the rotation period is twice the photometric period"
        )
        return RotationDecision(p_ph, 2 * p_ph, 2 * factor, text, tests)
    same = (
        f"P or 2P: the halves of the 2P fold agree within the noise "
        f"(F = {double.f_statistic:.3g}, p = {double.p_value:.2g} >= {ALPHA:g}), so the light "
        f"curve cannot tell a body that turns in P = {p_ph:.6g} s from one that looks alike "
        f"after half a turn and turns in 2P = {2 * p_ph:.6g} s"
    )
    if if_symmetric == "double":
        text = (
            f"{same}; the body is said to look alike after half a turn (--if-symmetric double): 2P"
        )
        return RotationDecision(p_ph, 2 * p_ph, 2 * factor, text, tests)
    if if_symmetric == "auto":
        maxima = maxima_per_cycle(series, p_ph, harmonics)
        if maxima <= 1:
            text = (
                f"{same}; the light curve shows one principal maximum per photometric cycle "
                "(maxima of at least half its range): taken as half a turn of a body that "
                "shows two maxima per turn (Harris et al. 1984; man-made bodies are often "
                "two-fold symmetric about their spin axis), so 2P is reported; "
                "--if-symmetric keep gives P"
            )
            return RotationDecision(p_ph, 2 * p_ph, 2 * factor, text, tests, ambiguous=True)
        text = (
            f"{same}; the light curve already shows {maxima} principal maxima per cycle, the "
            "two maxima per turn of a rotating body (Harris et al. 1984), so P is reported; "
            "--if-symmetric double gives 2P"
        )
        return RotationDecision(p_ph, p_ph, factor, text, tests, ambiguous=True)
    text = f"{same}; P is reported (--if-symmetric keep)"
    return RotationDecision(p_ph, p_ph, factor, text, tests, ambiguous=True)
