"""Multi-band, multi-harmonic Lomb-Scargle periodogram of light curves (plain arrays).

The model at frequency ``f`` is, independently in each band ``b``, a constant plus ``K``
harmonics, ``m_b(t) = c_b + sum_k a_bk cos(2 pi k f t) + b_bk sin(2 pi k f t)``, fitted by
weighted least squares (VanderPlas & Ivezic 2015, ApJ 812, 18, doi:10.1088/0004-637X/812/1/18,
the multi-term periodogram with ``nterms_base = 0`` shared terms). Its power is the fraction of
the chi-square about the weighted band means that the model explains,
``P(f) = 1 - sum_b chi2_b(f) / sum_b chi2_0b`` ("standard" normalisation).

Each band's ``chi2_b(f)`` comes from astropy's single-band
:class:`~astropy.timeseries.LombScargle` (``nterms = K``, method ``chi2``, or ``fastchi2``
for long series); the bands are
combined with their ``chi2_0b`` as weights. (astropy's ``LombScargleMultiband(method="fast")``
combines the same single-band powers but weights them by the sum of each band's squared powers,
which is not the chi-square of the joint model; hence the combination here.)
:func:`harmonic_chi2` is the same model fitted directly (numpy least squares): it serves the
peak refinement, the P/2P decision and the figures, and checks the astropy sum in the tests.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]
#: Degree of the polynomial in time fitted per band beside the harmonics in the refinement
#: (and the P/2P test): the detrending before the periodogram takes a little of the signal
#: with the pass's slow change, and leaves residuals correlated over the pass otherwise.
TREND_DEGREE = 3
#: Points per band above which astropy's ``fastchi2`` (extirpolation) beats ``chi2`` (direct).
FAST_ABOVE = 3000


@dataclass
class BandSeries:
    """Light-curve points of all bands, flattened (finite points only).

    Attributes
    ----------
    t_s
        (M,) time of each point since the first epoch [s].
    y
        (M,) value (detrended magnitude [mag] in :mod:`.period_io`).
    dy
        (M,) its standard deviation, > 0.
    band
        (M,) band index of each point, 0..B-1.
    n_bands
        B.
    """

    t_s: F64
    y: F64
    dy: F64
    band: I64
    n_bands: int

    @property
    def span_s(self) -> float:
        """Time span of the points [s]."""
        return float(self.t_s.max() - self.t_s.min())

    def permuted(self, rng: np.random.Generator) -> BandSeries:
        """The same points with (value, sigma) pairs shuffled among the epochs of each band."""
        y, dy = self.y.copy(), self.dy.copy()
        for b in range(self.n_bands):
            idx = np.flatnonzero(self.band == b)
            perm = rng.permutation(idx)
            y[idx], dy[idx] = self.y[perm], self.dy[perm]
        return BandSeries(self.t_s, y, dy, self.band, self.n_bands)


def frequency_grid(
    span_s: float, min_period_s: float, max_period_s: float, samples_per_peak: int = 5
) -> F64:
    """Regular frequency grid [Hz] from ``1/max_period_s`` to ``1/min_period_s``.

    The step is ``1 / (samples_per_peak * span_s)``: a peak of the periodogram is about
    ``1 / span_s`` wide (the Fourier resolution of a series of length ``span_s``), so each peak
    is sampled ``samples_per_peak`` times (VanderPlas 2018, ApJS 236, 16, section 7.1).
    """
    step = 1.0 / (samples_per_peak * span_s)
    f_lo, f_hi = 1.0 / max_period_s, 1.0 / min_period_s
    n = max(int(np.ceil((f_hi - f_lo) / step)) + 1, 2)
    return np.linspace(f_lo, f_hi, n)


def _chi2_0(series: BandSeries) -> F64:
    out = np.zeros(series.n_bands)
    for b in range(series.n_bands):
        m = series.band == b
        w = 1.0 / series.dy[m] ** 2
        mean = np.sum(w * series.y[m]) / np.sum(w)
        out[b] = np.sum(w * (series.y[m] - mean) ** 2)
    return out


def multiband_power(series: BandSeries, frequency_hz: F64, harmonics: int) -> F64:
    """Power ``1 - sum chi2_b(f) / sum chi2_0b`` at each frequency (module docstring).

    Bands with no more points than the ``2 harmonics + 1`` parameters of their model are
    left out; NaN everywhere when no band is left (or none varies).
    """
    from astropy.timeseries import LombScargle

    chi0 = _chi2_0(series)
    for b in range(series.n_bands):  # a band with no more points than parameters tells nothing
        if np.count_nonzero(series.band == b) <= 2 * harmonics + 1:
            chi0[b] = 0.0
    if not chi0.sum() > 0:
        return np.full(frequency_hz.size, np.nan)
    total = np.zeros(frequency_hz.size)
    for b in range(series.n_bands):
        m = series.band == b
        if chi0[b] <= 0:
            continue
        ls = LombScargle(series.t_s[m], series.y[m], series.dy[m], nterms=harmonics)
        method = "fastchi2" if m.sum() > FAST_ABOVE else "chi2"
        total += chi0[b] * ls.power(frequency_hz, method=method, normalization="standard")
    return np.asarray(total / chi0.sum(), dtype=np.float64)


def design_matrix(
    t_s: F64, frequency_hz: float, orders: list[int], phase_rad: F64 | None = None
) -> F64:
    """Columns ``1, cos(k x), sin(k x)`` for each harmonic order ``k``, with the rotation
    phase ``x = 2 pi f t - phase_rad`` (``phase_rad``: a known drift of the geometry, e.g. the
    azimuth of the phase-angle bisector about the spin axis, see :mod:`.synodic`)."""
    cols = [np.ones_like(t_s)]
    x = 2 * np.pi * frequency_hz * t_s - (0.0 if phase_rad is None else phase_rad)
    for k in orders:
        arg = k * x
        cols += [np.cos(arg), np.sin(arg)]
    return np.stack(cols, axis=1)


def _with_trend(series: BandSeries, m: NDArray[np.bool_], x: F64, degree: int) -> F64:
    """``x`` with the columns ``u^1..u^degree``, ``u`` the time scaled to -1..1 over the span."""
    if degree <= 0:
        return x
    u = 2 * (series.t_s[m] - series.t_s.min()) / max(series.span_s, 1e-12) - 1
    return np.hstack([x, np.stack([u**d for d in range(1, degree + 1)], axis=1)])


def harmonic_chi2(
    series: BandSeries,
    frequency_hz: float,
    orders: list[int],
    phase_rad: F64 | None = None,
    trend_degree: int = 0,
) -> tuple[float, int, list[F64]]:
    """Weighted least-squares fit of the harmonics ``orders`` of ``frequency_hz`` per band,
    with a polynomial in time per band beside the constant (the coefficients of the
    harmonics come first, the trend's last).

    Parameters
    ----------
    series
        The light curves.
    frequency_hz
        The fundamental frequency [Hz].
    orders
        The harmonics fitted (1 = the fundamental).
    phase_rad
        A phase per point added to the harmonics' argument [rad] (see
        :func:`design_matrix`), or None.
    trend_degree
        Degree of the polynomial trend in time per band (0: the constant alone).

    Returns
    -------
    chi2
        The summed chi-square of the fit.
    n_parameters
        Parameters fitted, all bands together.
    coefficients
        Per band: ``[c, a_1, b_1, a_2, b_2, ...]`` in the order of ``orders``.
    """
    chi2, npar, coefs = 0.0, 0, []
    for b in range(series.n_bands):
        m = series.band == b
        w = 1.0 / series.dy[m]
        ph = None if phase_rad is None else phase_rad[m]
        x = _with_trend(
            series, m, design_matrix(series.t_s[m], frequency_hz, orders, ph), trend_degree
        )
        beta, *_ = np.linalg.lstsq(x * w[:, None], series.y[m] * w, rcond=None)
        chi2 += float(np.sum(((series.y[m] - x @ beta) * w) ** 2))
        npar += x.shape[1]
        coefs.append(beta)
    return chi2, npar, coefs


def local_maxima(power: F64, count: int) -> I64:
    """Indices of the ``count`` highest local maxima of ``power`` (end points included)."""
    p = np.concatenate([[-np.inf], power, [-np.inf]])
    idx = np.flatnonzero((p[1:-1] > p[:-2]) & (p[1:-1] >= p[2:]))
    return idx[np.argsort(power[idx])[::-1][:count]].astype(np.int64)


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
        Lag-1 autocorrelation of the residuals (:func:`residual_lag1_correlation`).
    """

    frequency_hz: float
    frequency_std_hz: float
    chi2: float
    dof: int
    residual_correlation: float = 0.0


def refine_peak(
    series: BandSeries,
    frequency_hz: float,
    orders: list[int],
    phase_rad: F64 | None = None,
    trend_degree: int = TREND_DEGREE,
    within: tuple[float, float] | None = None,
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
        return harmonic_chi2(series, f, orders, phase_rad, trend_degree)[0]

    half = 0.1 / series.span_s
    lo, hi = frequency_hz - half, frequency_hz + half
    if within is not None:
        lo, hi = max(lo, float(within[0])), min(hi, float(within[1]))
    found = minimize_scalar(chi, bounds=(lo, hi), method="bounded", options={"xatol": 1e-6 * half})
    best = float(found.x)
    chi2, npar, coefs = harmonic_chi2(series, best, orders, phase_rad, trend_degree)
    dof = max(series.t_s.size - npar - 1, 1)
    step, std = half / 10, float("nan")
    for _ in range(2):
        c2 = (chi(best + step) + chi(best - step) - 2 * chi2) / (2 * step**2)
        if not c2 > 0:
            break
        std = float(np.sqrt((chi2 / dof) / c2))
        step = min(2 * std, half)
    rho, residuals = residual_lag1_correlation(series, best, orders, coefs, phase_rad, trend_degree)
    inflation = red_noise_inflation(series, best, orders, coefs, residuals)
    return Peak(best, std * inflation, chi2, dof, rho)


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


def residual_lag1_correlation(
    series: BandSeries,
    frequency_hz: float,
    orders: list[int],
    coefs: list[F64],
    phase_rad: F64 | None = None,
    trend_degree: int = 0,
) -> tuple[float, F64]:
    """Lag-1 autocorrelation of the normalised residuals, consecutive points of each band
    pooled (``sum r_i r_(i+1) / sum r_i^2``, capped at 0.99), and the normalised residuals
    (in the order of the series' points).

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
    phase_rad
        A phase per point added to the harmonics' argument [rad], or None.
    trend_degree
        Degree of the polynomial trend in time per band.
    """
    num = den = 0.0
    out = np.zeros(series.y.size)
    for b, beta in enumerate(coefs):
        m = series.band == b
        ph = None if phase_rad is None else phase_rad[m]
        x = _with_trend(
            series, m, design_matrix(series.t_s[m], frequency_hz, orders, ph), trend_degree
        )
        order = np.argsort(series.t_s[m])
        res = (series.y[m] - x @ beta) / series.dy[m]
        out[m] = res
        r = res[order]
        num += float(np.sum(r[1:] * r[:-1]))
        den += float(np.sum(r**2))
    return (min(num / den, 0.99) if den > 0 else 0.0), out
