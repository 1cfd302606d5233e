"""The best peak refined, with a model that fits the light curve, and its uncertainty.

:func:`refine_peak` minimises the chi-square of given harmonics and a polynomial trend per
band near a periodogram peak and derives the frequency's standard deviation from its
curvature, the residuals' level and their spectrum near the harmonics.
:func:`refine_with_model` first chooses that model: the periodogram's ``K`` harmonics are
extended by :func:`harmonics_needed` and the cubic trend by :func:`trend_degree_needed`
while each added term is significant (F-tests). With too few terms the light curve's
higher harmonics and the pass's slow change the cubic misses stay in the residuals: their
deterministic power inflated the reduced chi-square (up to ~500 on blind draws) and so the
standard deviation, while shifting the frequency by what that power happens to correlate
with (BENCHMARKS.md, "Period: calibration over blind draws").
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from speclight.estimate.period.period_decision import ALPHA, nested_f_test
from speclight.estimate.period.periodogram import (
    F64,
    TREND_DEGREE,
    BandSeries,
    harmonic_chi2,
    residual_lag1_correlation,
)

#: Most harmonics of a refinement's model: a light curve with glints has many.
MAX_HARMONICS = 24
#: Highest degree of the trend of a refinement's model. The degree is also kept below
#: ``pi`` times the cycles in the span: a Legendre polynomial of degree ``d`` oscillates about
#: ``d / pi`` times per span at mid-pass, so the trend stays slower than the rotation. Where
#: the trend and the harmonics are alike all the same, the curvature of the profile
#: chi-square (all linear terms refitted at each frequency) widens the standard deviation.
MAX_TREND_DEGREE = 20
#: Passes of model choice and refinement in :func:`refine_with_model`.
MODEL_PASSES = 3


@dataclass
class Peak:
    """A refined periodogram peak.

    Attributes
    ----------
    frequency_hz, frequency_std_hz
        Best frequency and its standard deviation [Hz].
    chi2, dof
        Chi-square of the fit at the best frequency and its degrees of freedom.
    residual_correlation
        Lag-1 autocorrelation of the residuals (:func:`.periodogram.residual_lag1_correlation`).
    white_std_hz
        The standard deviation from the curvature alone, with the sigmas as given [Hz].
    noise_factor
        ``frequency_std_hz / white_std_hz``: the square root of the reduced chi-square
        times the coloured-noise factor (:func:`refine_peak`).
    orders, trend_degree, amplitude_change
        The model: its harmonics, the degree of its trend per band, and whether the
        harmonics' amplitude changes linearly over the pass
        (:func:`.periodogram.band_design`).
    """

    frequency_hz: float
    frequency_std_hz: float
    chi2: float
    dof: int
    residual_correlation: float = 0.0
    white_std_hz: float = float("nan")
    noise_factor: float = 1.0
    orders: list[int] = field(default_factory=lambda: [1])
    trend_degree: int = TREND_DEGREE
    amplitude_change: bool = False


def refine_peak(
    series: BandSeries,
    frequency_hz: float,
    orders: list[int],
    phase_rad: F64 | None = None,
    trend_degree: int = TREND_DEGREE,
    within: tuple[float, float] | None = None,
    amplitude_change: bool = False,
) -> Peak:
    """Best frequency near ``frequency_hz`` and its standard deviation.

    The chi-square of the model with the harmonics ``orders`` and a polynomial trend of
    ``trend_degree`` per band is minimised over ``+-0.1 / span`` around ``frequency_hz`` (a
    tenth of the peak width; scipy's bounded Brent search, to 1e-6 of that window), cut to
    ``within`` (the searched frequency range [Hz], if given). Its
    curvature at the minimum, ``c2`` of ``chi2(f) ~ chi2_min + c2 (f - f0)^2``, comes from a
    central difference whose step is set to twice the resulting standard deviation (two
    passes). The standard deviation follows from ``delta chi2 = 1`` after scaling the
    chi-square by its reduced value at the minimum (so that mis-stated sigmas and model
    misfit widen it): ``sigma_f = sqrt(chi2_min / dof / c2)`` (Press et al., Numerical
    Recipes, 15.6). That rule assumes independent residuals; a light curve that changes over
    a pass leaves residuals correlated over many epochs, so ``sigma_f`` is multiplied by
    :func:`red_noise_inflation`, from the residuals' spectrum near the harmonics.

    Parameters
    ----------
    series
        The light curves.
    frequency_hz
        The peak's frequency on the grid [Hz].
    orders
        The harmonics of the model.
    phase_rad
        A phase per point added to the harmonics' argument [rad], or None.
    trend_degree
        Degree of the polynomial trend in time per band.
    within
        The searched frequency range (low, high) [Hz], or None.
    """
    from scipy.optimize import minimize_scalar

    def chi(f: float) -> float:
        return harmonic_chi2(series, f, orders, phase_rad, trend_degree, amplitude_change)[0]

    half = 0.1 / series.span_s
    lo, hi = frequency_hz - half, frequency_hz + half
    if within is not None:
        lo, hi = max(lo, float(within[0])), min(hi, float(within[1]))
    found = minimize_scalar(chi, bounds=(lo, hi), method="bounded", options={"xatol": 1e-6 * half})
    best = float(found.x)
    chi2, npar, coefs = harmonic_chi2(
        series, best, orders, phase_rad, trend_degree, amplitude_change
    )
    dof = max(series.t_s.size - npar - 1, 1)
    step, std = half / 10, float("nan")
    for _ in range(2):
        c2 = (chi(best + step) + chi(best - step) - 2 * chi2) / (2 * step**2)
        if not c2 > 0:
            break
        std = float(np.sqrt((chi2 / dof) / c2))
        step = min(2 * std, half)
    rho, residuals = residual_lag1_correlation(
        series, best, orders, coefs, phase_rad, trend_degree, amplitude_change
    )
    inflation = red_noise_inflation(series, best, orders, coefs, residuals)
    white = std / np.sqrt(chi2 / dof)
    factor = float(np.sqrt(chi2 / dof) * inflation)
    return Peak(
        best, std * inflation, chi2, dof, rho, white, factor, list(orders), trend_degree,
        amplitude_change,
    )  # fmt: skip


def red_noise_inflation(
    series: BandSeries,
    frequency_hz: float,
    orders: list[int],
    coefs: list[F64],
    residuals: F64,
) -> float:
    """Factor on ``sigma_f`` for residuals that are not white (1 when they are).

    The frequency's variance is inversely proportional to the harmonics' information,
    ``sum_k k^2 A_k^2 / S(k f)``, with ``S`` the noise's power spectral density (Kay,
    Fundamentals of Statistical Signal Processing I, 1993, ch. 3, the Cramer-Rao bound in
    coloured Gaussian noise). ``S`` is measured on the residuals themselves (normalised by
    their sigmas, all bands pooled): ``R_k`` is the mean Lomb-Scargle power of the residuals
    in the side bands ``1.5/span <= |f' - k f| <= 6/span`` of each harmonic over their mean
    power from ``1/span`` to the Nyquist frequency of the median spacing (the local noise
    level of Montgomery & O'Donoghue 1999, DSSN 13, 28, as a ratio to the white level). The
    factor is ``sqrt(sum w_k / sum (w_k / R_k))`` with ``w_k = k^2 A_k^2``, the amplitudes
    ``A_k`` averaged over the bands with weights ``sum 1/dy^2``; it is not allowed below 1.

    Parameters
    ----------
    series
        The light curves.
    frequency_hz
        The fitted frequency [Hz].
    orders
        The harmonics of the model.
    coefs
        The fit's coefficients per band (:func:`harmonic_chi2`).
    residuals
        The normalised residuals, in the order of the series' points.
    """
    from astropy.timeseries import LombScargle

    amp2 = np.zeros(len(orders))
    wsum = 0.0
    k = len(orders)
    for b, beta in enumerate(coefs):
        w = float(np.sum(1.0 / series.dy[series.band == b] ** 2))
        amp2 += w * (beta[1 : 2 * k + 1 : 2] ** 2 + beta[2 : 2 * k + 2 : 2] ** 2)
        wsum += w
    order = np.asarray(orders, dtype=float)
    weight = order**2 * amp2 / wsum
    if np.sum(weight) <= 0:
        return 1.0
    span = series.span_s
    dt = float(np.median(np.diff(np.unique(series.t_s))))
    ls = LombScargle(series.t_s, residuals, fit_mean=True, center_data=True)
    broad = np.linspace(1.0 / span, 0.5 / dt, 2000)
    level = float(np.mean(ls.power(broad, method="fast")))
    side = np.concatenate([np.linspace(1.5, 6.0, 10), -np.linspace(1.5, 6.0, 10)]) / span
    ratio = np.empty(k)
    for j, o in enumerate(order):
        near = o * frequency_hz + side
        near = near[(near > 0) & (near < 0.5 / dt)]
        ratio[j] = float(np.mean(ls.power(near, method="cython"))) / level if near.size else 1.0
    ratio = np.maximum(ratio, 1e-3)
    return max(float(np.sqrt(np.sum(weight) / np.sum(weight / ratio))), 1.0)


def harmonics_needed(
    series: BandSeries, frequency_hz: float, start: int, alpha: float = ALPHA,
    trend_degree: int = TREND_DEGREE, phase_rad: F64 | None = None,
) -> list[int]:  # fmt: skip
    """Harmonics ``1..H`` of ``frequency_hz``, ``H >= start`` grown while the next one is
    significant (F-test at ``alpha``, :func:`.period_decision.nested_f_test`), at most
    :data:`MAX_HARMONICS` and below the Nyquist frequency of the median spacing (a harmonic
    above it aliases onto lower frequencies: tens of them fitted one cosmic ray); with a
    trend of ``trend_degree`` per band and ``phase_rad`` added to the harmonics' argument
    (:func:`refine_peak`)."""
    dt = float(np.median(np.diff(np.unique(series.t_s))))
    top = min(MAX_HARMONICS, int(np.ceil(0.5 / (dt * frequency_hz))) - 1)
    h = start
    chi, npar, _ = harmonic_chi2(
        series, frequency_hz, list(range(1, h + 1)), phase_rad, trend_degree
    )
    while h < top:
        chi2, npar2, _ = harmonic_chi2(
            series, frequency_hz, list(range(1, h + 2)), phase_rad, trend_degree
        )
        if not nested_f_test(chi, npar, chi2, npar2, series.t_s.size)[1] < alpha:
            break
        h, chi, npar = h + 1, chi2, npar2
    return list(range(1, h + 1))


def trend_degree_needed(
    series: BandSeries, frequency_hz: float, orders: list[int], alpha: float = ALPHA,
    phase_rad: F64 | None = None,
) -> int:  # fmt: skip
    """Degree of the trend per band beside the harmonics ``orders``: from
    :data:`.periodogram.TREND_DEGREE`, grown while the next degree, or the next two together
    (a slow change symmetric about mid-pass has only even Legendre terms), is significant
    (F-test at ``alpha``), at most :data:`MAX_TREND_DEGREE` and below ``pi`` times the
    cycles in the span."""
    cap = min(int(np.ceil(np.pi * series.span_s * frequency_hz)) - 1, MAX_TREND_DEGREE)
    d = TREND_DEGREE
    chi, npar, _ = harmonic_chi2(series, frequency_hz, orders, phase_rad, d)
    while True:
        for step in (1, 2):  # a change symmetric about mid-pass needs only even degrees
            if d + step > cap:
                return d
            chi2, npar2, _ = harmonic_chi2(series, frequency_hz, orders, phase_rad, d + step)
            if nested_f_test(chi, npar, chi2, npar2, series.t_s.size)[1] < alpha:
                d, chi, npar = d + step, chi2, npar2
                break
        else:
            return d


def refine_with_model(
    series: BandSeries,
    frequency_hz: float,
    harmonics: int,
    within: tuple[float, float] | None = None,
    phase_rad: F64 | None = None,
) -> Peak:
    """The peak near ``frequency_hz`` refined (:func:`refine_peak`) with the ``harmonics``
    of the periodogram and a cubic trend, then again with the model the light curve needs
    at that frequency (:func:`harmonics_needed`, :func:`trend_degree_needed`), up to
    :data:`MODEL_PASSES` times while the model changes (a better model moves the frequency,
    and the model's terms are tested at the frequency found), all within the periodogram's
    peak, ``+-0.5 / span`` of ``frequency_hz``. A model whose chi-square has no minimum of
    positive curvature there
    is not taken (the last pass's peak is kept).

    Parameters
    ----------
    series
        The light curves.
    frequency_hz
        The peak's frequency on the grid [Hz].
    harmonics
        ``K``, the periodogram's harmonics.
    within
        The searched frequency range (low, high) [Hz], or None.
    phase_rad
        A phase per point added to the harmonics' argument [rad] (the synodic fit,
        :mod:`.synodic`), or None.
    """
    half = 0.5 / series.span_s  # the passes stay within the periodogram's peak
    lo, hi = frequency_hz - half, frequency_hz + half
    if within is not None:
        lo, hi = max(lo, float(within[0])), min(hi, float(within[1]))
    within = (lo, hi)
    model: tuple[list[int], int, bool] = (list(range(1, harmonics + 1)), TREND_DEGREE, False)
    peak = refine_peak(series, frequency_hz, model[0], phase_rad, within=within)
    for _ in range(MODEL_PASSES):
        f = peak.frequency_hz
        orders = harmonics_needed(series, f, harmonics, phase_rad=phase_rad)
        degree = trend_degree_needed(series, f, orders, phase_rad=phase_rad)
        change = amplitude_change_needed(series, f, orders, degree, phase_rad=phase_rad)
        chosen = (orders, degree, change)
        if chosen == model:
            break
        model = chosen
        better = refine_peak(series, f, orders, phase_rad, degree, within, change)
        if not np.isfinite(better.frequency_std_hz):  # no minimum with a positive curvature
            break
        peak = better
    return peak


def amplitude_change_needed(
    series: BandSeries, frequency_hz: float, orders: list[int], trend_degree: int,
    alpha: float = ALPHA, phase_rad: F64 | None = None,
) -> bool:  # fmt: skip
    """Whether the harmonics' amplitude changing linearly over the pass
    (:func:`.periodogram.band_design`, one parameter per band) is significant beside the
    harmonics ``orders`` and the trend (F-test at ``alpha``)."""
    chi, npar, _ = harmonic_chi2(series, frequency_hz, orders, phase_rad, trend_degree)
    chi2, npar2, _ = harmonic_chi2(series, frequency_hz, orders, phase_rad, trend_degree, True)
    return bool(nested_f_test(chi, npar, chi2, npar2, series.t_s.size)[1] < alpha)
