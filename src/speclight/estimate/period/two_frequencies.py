"""Tumbling: a light curve with two fundamental frequencies.

A body in non-principal-axis rotation (a tumbler) shows a light curve that is periodic in
two frequencies, the rotation and the precession ones (for a torque-free rigid body,
``1/P_psi`` and ``1/P_phi``), and in their combinations ``j f_1 + k f_2``: a
two-dimensional Fourier series (Pravec et al. 2005, Icarus 173, 108,
doi:10.1016/j.icarus.2004.07.021, eq. 1; Kaasalainen 2001, A&A 376, 302). One period then
fits only part of the light curve. The test:

1. the harmonics ``1..H`` of the rotation frequency ``f_1`` (and a cubic trend per band)
   are fitted and subtracted, ``H >= 2K`` grown while the next harmonic is significant (a
   light curve with glints has many; their aliases would pass for a second frequency);
2. the residuals' multi-band periodogram (one harmonic) on the same grid, away
   (``>= 2.5/span``) from the harmonics of ``f_1``, gives a second frequency ``f_2``, refined
   as the first, then with the mixed terms of step 3; it counts
   only with a false-alarm probability below 1 % (:mod:`.analytic_fap`, with the residuals'
   own noise level beside it, so a light curve that changes shape over the pass does not
   make a second frequency);
3. a nested-model F-test: the harmonics of both frequencies (``K + 1`` of ``f_2``) against
   the same model plus their mixed combinations ``j f_1 + k f_2`` (``j != 0``, ``k >= 1``,
   ``|j| + k <= K + 1``; residual variance
   from the data, and residuals correlated from epoch to epoch (a light curve that changes
   over the pass) counted as fewer independent points); tumbling when its p-value is below
   ``alpha`` (0.001).

The combinations of largest amplitude are reported. Which of ``f_1`` and ``f_2`` is the
rotation and which the precession frequency a light curve alone does not say.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from speclight.estimate.period.peak_refinement import harmonics_needed, refine_peak
from speclight.estimate.period.period_decision import nested_f_test
from speclight.estimate.period.periodogram import (
    F64,
    TREND_DEGREE,
    BandSeries,
    _with_trend,
    design_matrix,
    local_maxima,
    multiband_power,
    weighted_lstsq,
)

#: False-alarm probability below which the second frequency counts.
SECOND_FAP = 0.01
#: Combinations reported.
N_COMBINATIONS = 6
#: p-value of the mixed terms at the unrefined second frequency above which it is not
#: refined (the refinement only lowers the chi-square of the full model).
QUICK_P = 0.1
#: Half width of the frequencies left out around each harmonic, in units of ``1/span``.
EXCLUDE_WIDTH = 2.5


@dataclass
class TumblingTest:
    """Result of the two-frequency test (module docstring)."""

    detected: bool
    frequencies_hz: list[float]
    second_fap: float | None
    f_statistic: float | None
    p_value: float | None
    combinations: list[dict[str, float]] = field(default_factory=list)
    text: str = ""


def _combination_columns(
    t_s: F64, f1: float, f2: float, m: int, mixed: bool
) -> tuple[F64, list[tuple[int, int]]]:
    """Columns of ``j f1 + k f2``, ``k >= 1``, ``|j| + k <= m``: the mixed ones (``j != 0``)
    or the harmonics of ``f2`` (``j == 0``)."""
    pairs = [
        (j, k) for k in range(1, m + 1) for j in range(-(m - k), m - k + 1) if (j != 0) == mixed
    ]
    cols = []
    for j, k in pairs:
        arg = 2 * np.pi * (j * f1 + k * f2) * t_s
        cols += [np.cos(arg), np.sin(arg)]
    return np.stack(cols, axis=1), pairs


def _fit(
    series: BandSeries, f1: float, orders: list[int], f2: float | None, m: int, mixed: bool
) -> tuple[float, int, list[F64], F64]:
    """Chi-square, parameters, coefficients per band and residuals of the harmonics
    ``orders`` of ``f1`` with a cubic trend, plus (``f2`` given) the harmonics of ``f2`` up
    to ``m``, plus (``mixed``) the mixed combinations."""
    chi2, npar, coefs = 0.0, 0, []
    resid = np.zeros(series.y.size)
    for b in range(series.n_bands):
        mk = series.band == b
        t = series.t_s[mk]
        x = _with_trend(series, mk, design_matrix(t, f1, orders), TREND_DEGREE)
        if f2 is not None:
            x = np.hstack([x, _combination_columns(t, f1, f2, m, False)[0]])
            if mixed:
                x = np.hstack([x, _combination_columns(t, f1, f2, m, True)[0]])
        w = 1.0 / series.dy[mk]
        beta = weighted_lstsq(x, series.y[mk], w)
        resid[mk] = series.y[mk] - x @ beta
        chi2 += float(np.sum((resid[mk] * w) ** 2))
        npar += x.shape[1]
        coefs.append(beta)
    return chi2, npar, coefs, resid


def _lag1(series: BandSeries, resid: F64) -> float:
    """Lag-1 correlation of the normalised residuals, consecutive points of each band pooled
    (at most 0.99)."""
    num = den = 0.0
    for b in range(series.n_bands):
        r = resid[series.band == b] / series.dy[series.band == b]
        num += float(np.sum(r[1:] * r[:-1]))
        den += float(np.sum(r**2))
    return min(num / den, 0.99) if den > 0 else 0.0


def _reduced(f2: float, f1: float, f_min: float) -> float:
    """The lowest frequency ``|f2 - j f1|`` (``j`` integer) within the grid: the pairs
    ``(f1, f2)`` and ``(f1, |f2 - j f1|)`` span the same combinations, and the residuals'
    best peak may be a combination (Pravec et al. 2005 pick the lowest)."""
    r = abs(f2 - round(f2 / f1) * f1)
    return r if r >= f_min else f2


def _refined(series: BandSeries, f1: float, orders: list[int], f2: float, m: int) -> float:
    """``f2`` minimising the chi-square of the two-frequency model with its mixed
    combinations, within a quarter of a peak width (scipy's bounded Brent search)."""
    from scipy.optimize import minimize_scalar

    half = 0.25 / series.span_s
    found = minimize_scalar(
        lambda f: _fit(series, f1, orders, f, m, True)[0],
        bounds=(f2 - half, f2 + half), method="bounded", options={"xatol": 1e-3 * half},
    )  # fmt: skip
    return float(found.x)


def tumbling_test(
    series: BandSeries, frequency_hz: F64, rotation_hz: float, harmonics: int, alpha: float
) -> TumblingTest:
    """Two fundamental frequencies or one? (module docstring).

    Parameters
    ----------
    series
        The detrended light curves.
    frequency_hz
        The frequency grid searched [Hz].
    rotation_hz
        ``f_1``, the rotation frequency found [Hz].
    harmonics
        ``K``.
    alpha
        p-value below which the combinations are significant.
    """
    from speclight.estimate.period.analytic_fap import analytic_fap

    orders = harmonics_needed(series, rotation_hz, 2 * harmonics, alpha)
    _, _, _, resid = _fit(series, rotation_hz, orders, None, 0, False)
    rest = BandSeries(series.t_s, resid, series.dy, series.band, series.n_bands)
    power = multiband_power(rest, frequency_hz, 1)
    width = EXCLUDE_WIDTH / series.span_s
    near = np.abs(frequency_hz[:, None] - rotation_hz * np.arange(1, len(orders) + 2)) < width
    power = np.where(np.any(near, axis=1) | ~np.isfinite(power), -np.inf, power)
    none = TumblingTest(False, [rotation_hz], None, None, None, text="one frequency")
    if not np.any(np.isfinite(power)):
        return none
    k = int(local_maxima(power, 1)[0])
    fap2 = analytic_fap(rest, frequency_hz, 1, float(frequency_hz[k])).fap(float(power[k]))
    f2 = refine_peak(rest, float(frequency_hz[k]), [1]).frequency_hz
    f2 = _reduced(f2, rotation_hz, float(frequency_hz[0]))
    none.second_fap, none.frequencies_hz = fap2, [rotation_hz, f2]
    if k == 0 or not fap2 < SECOND_FAP:
        why = (
            "is the longest period searched (a change over the pass, not a frequency)"
            if k == 0
            else f"has a false-alarm probability {fap2:.2g} >= {SECOND_FAP:g}"
        )
        none.text = f"one frequency: the residuals' best peak ({1 / f2:.6g} s) {why}"
        return none
    m = harmonics + 1
    chi_r, p_r, _, _ = _fit(series, rotation_hz, orders, f2, m, False)
    chi_f, p_f, _, resid = _fit(series, rotation_hz, orders, f2, m, True)
    if nested_f_test(chi_r, p_r, chi_f, p_f, series.t_s.size, _lag1(series, resid))[1] < QUICK_P:
        f2 = _refined(series, rotation_hz, orders, f2, m)  # worth refining
    chi_r, p_r, _, _ = _fit(series, rotation_hz, orders, f2, m, False)
    chi_f, p_f, coefs, resid = _fit(series, rotation_hz, orders, f2, m, True)
    rho = _lag1(series, resid)
    stat, p = nested_f_test(chi_r, p_r, chi_f, p_f, series.t_s.size, rho)
    pairs = _combination_columns(series.t_s[:1], rotation_hz, f2, m, True)[1]
    amp = np.zeros(len(pairs))
    wsum = 0.0
    n_before = p_r // series.n_bands
    for b, beta in enumerate(coefs):
        w = float(np.sum(1.0 / series.dy[series.band == b] ** 2))
        extra = beta[n_before:]
        amp += w * np.hypot(extra[0::2], extra[1::2])
        wsum += w
    amp /= max(wsum, 1e-300)
    top = np.argsort(amp)[::-1][:N_COMBINATIONS]
    combos = [
        {"j": pairs[i][0], "k": pairs[i][1],
         "frequency_hz": pairs[i][0] * rotation_hz + pairs[i][1] * f2,
         "amplitude_mag": float(amp[i])}
        for i in top
    ]  # fmt: skip
    detected = p < alpha
    text = (
        f"two fundamental frequencies, {rotation_hz:.6g} Hz ({1 / rotation_hz:.6g} s) and "
        f"{f2:.6g} Hz ({1 / f2:.6g} s; residual peak false-alarm probability {fap2:.2g}), "
        f"and their mixed combinations j f1 + k f2 fit (F = {stat:.3g}, p = {p:.2g} < "
        f"{alpha:g}): non-principal-axis rotation (tumbling, Pravec et al. 2005); "
        "period_s is the stronger one; which of the two is the rotation and which the "
        "precession the light curve does not say"
        if detected
        else f"one frequency: a second one at {1 / f2:.6g} s, but its mixed combinations "
        f"with the first do not fit significantly better (F = {stat:.3g}, p = {p:.2g} >= "
        f"{alpha:g}): two independent signals or a change over the pass, not tumbling"
    )
    return TumblingTest(detected, [rotation_hz, f2], fap2, stat, p, combos, text)
