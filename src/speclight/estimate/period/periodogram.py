"""Multi-band, multi-harmonic Lomb-Scargle periodogram of light curves (plain arrays).

The model at frequency ``f`` is, independently in each band ``b``, a constant plus ``K``
harmonics, ``m_b(t) = c_b + sum_k a_bk cos(2 pi k f t) + b_bk sin(2 pi k f t)``, fitted by
weighted least squares (VanderPlas & Ivezic 2015, ApJ 812, 18, doi:10.1088/0004-637X/812/1/18,
the multi-term periodogram with ``nterms_base = 0`` shared terms). Its power is the fraction of
the chi-square about the weighted band means that the model explains,
``P(f) = 1 - sum_b chi2_b(f) / sum_b chi2_0b`` ("standard" normalisation).

Each band's ``chi2_b(f)`` comes from astropy's single-band
:class:`~astropy.timeseries.LombScargle` (``nterms = K``, method ``chi2``, or for long series
``fastchi2``, and ``fast`` (Press & Rybicki 1989) when ``K = 1``); the bands are
combined with their ``chi2_0b`` as weights. (astropy's ``LombScargleMultiband(method="fast")``
combines the same single-band powers but weights them by the sum of each band's squared powers,
which is not the chi-square of the joint model; hence the combination here.)
:func:`harmonic_chi2` is the same model fitted directly (numpy least squares): it serves the
peak refinement (:mod:`.peak_refinement`), the P/2P decision and the figures, and checks the
astropy sum in the tests.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]
#: Degree of the polynomial in time fitted per band beside the harmonics in the P/2P test and
#: the outlier and tumbling tests, and the refinement's lowest (:mod:`.peak_refinement`): the
#: detrending before the periodogram takes a little of the signal with the pass's slow
#: change, and leaves residuals correlated over the pass otherwise.
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
        method = "chi2" if m.sum() <= FAST_ABOVE else "fast" if harmonics == 1 else "fastchi2"
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
    """``x`` with the columns ``P_1(u)..P_degree(u)`` (Legendre polynomials: well conditioned
    at high degrees), ``u`` the time scaled to -1..1 over the span."""
    if degree <= 0:
        return x
    u = 2 * (series.t_s[m] - series.t_s.min()) / max(series.span_s, 1e-12) - 1
    return np.hstack([x, np.polynomial.legendre.legvander(u, degree)[:, 1:]])


def weighted_lstsq(x: F64, y: F64, w: F64) -> F64:
    """Least-squares coefficients of ``(x * w) beta ~ y * w``, through the normal equations
    (``p x p`` for ``N x p`` columns: many times faster than an SVD of the tall matrix for
    the few columns here), solved by SVD so that collinear columns stay finite."""
    a = x * w[:, None]
    beta, *_ = np.linalg.lstsq(a.T @ a, a.T @ (y * w), rcond=None)
    return np.asarray(beta, dtype=np.float64)


def band_design(
    series: BandSeries,
    m: NDArray[np.bool_],
    frequency_hz: float,
    orders: list[int],
    phase_rad: F64 | None = None,
    trend_degree: int = 0,
    amplitude_change: bool = False,
) -> F64:
    """Design matrix of the points ``m`` (one band): :func:`design_matrix` with the trend
    (:func:`_with_trend`) and, with ``amplitude_change``, one more column ``u h(t)``: the
    band's fitted harmonic curve ``h`` (a first fit without it) times the time ``u`` scaled
    to -1..1, a light curve whose amplitude changes linearly over the pass (as with the
    phase angle, Zappala et al. 1990, A&A 231, 548). It is orthogonal to a shift of the
    frequency (which moves ``h`` by its quadrature ``t h'``), so it takes no information from
    the frequency."""
    ph = None if phase_rad is None else phase_rad[m]
    x = _with_trend(series, m, design_matrix(series.t_s[m], frequency_hz, orders, ph), trend_degree)
    if not amplitude_change:
        return x
    beta = weighted_lstsq(x, series.y[m], 1.0 / series.dy[m])
    k2 = 2 * len(orders)
    h = x[:, 1 : 1 + k2] @ beta[1 : 1 + k2]
    u = 2 * (series.t_s[m] - series.t_s.min()) / max(series.span_s, 1e-12) - 1
    return np.hstack([x, (u * h)[:, None]])


def harmonic_chi2(
    series: BandSeries,
    frequency_hz: float,
    orders: list[int],
    phase_rad: F64 | None = None,
    trend_degree: int = 0,
    amplitude_change: bool = False,
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
    amplitude_change
        Let the harmonics' amplitude change linearly over the pass (:func:`band_design`).

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
        x = band_design(series, m, frequency_hz, orders, phase_rad, trend_degree, amplitude_change)
        beta = weighted_lstsq(x, series.y[m], w)
        chi2 += float(np.sum(((series.y[m] - x @ beta) * w) ** 2))
        npar += x.shape[1]
        coefs.append(beta)
    return chi2, npar, coefs


def local_maxima(power: F64, count: int) -> I64:
    """Indices of the ``count`` highest local maxima of ``power`` (end points included)."""
    p = np.concatenate([[-np.inf], power, [-np.inf]])
    idx = np.flatnonzero((p[1:-1] > p[:-2]) & (p[1:-1] >= p[2:]))
    return idx[np.argsort(power[idx])[::-1][:count]].astype(np.int64)


def residual_lag1_correlation(
    series: BandSeries,
    frequency_hz: float,
    orders: list[int],
    coefs: list[F64],
    phase_rad: F64 | None = None,
    trend_degree: int = 0,
    amplitude_change: bool = False,
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
    amplitude_change
        Whether the model has the amplitude-change column (:func:`.periodogram.band_design`).
    """
    num = den = 0.0
    out = np.zeros(series.y.size)
    for b, beta in enumerate(coefs):
        m = series.band == b
        x = band_design(series, m, frequency_hz, orders, phase_rad, trend_degree, amplitude_change)
        order = np.argsort(series.t_s[m])
        res = (series.y[m] - x @ beta) / series.dy[m]
        out[m] = res
        r = res[order]
        num += float(np.sum(r[1:] * r[:-1]))
        den += float(np.sum(r**2))
    return (min(num / den, 0.99) if den > 0 else 0.0), out
