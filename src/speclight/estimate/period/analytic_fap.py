"""False-alarm probability of a periodogram peak without bootstrap: Baluev (2008), with the
noise level beside the peak for residuals that are not white.

**White noise.** The multi-band multi-harmonic power ``z(f)`` (:mod:`.periodogram`, the
fraction of the chi-square about the band means explained by ``K`` harmonics in each of
``B`` bands) is, at one frequency and for Gaussian noise, Beta-distributed with
``(nu/2, (N_H - nu)/2)`` degrees of freedom, ``nu = 2 K B`` the parameters the harmonics
add and ``N_H = N - B`` the degrees of freedom left by the band means (the F-test of a
linear model; the standard normalisation makes it free of the noise's scale). Its maximum
over a band of frequencies exceeds ``z`` with probability at most

``FAP(z) = 1 - (1 - P_1(z)) exp(-tau(z))``,
``tau(z) = W z^((nu-1)/2) (1-z)^((N_H-nu-1)/2) Gamma(N_H/2) / (Gamma((N_H-nu+1)/2) Gamma(nu/2))``,

``P_1`` the single-frequency tail and ``tau`` the expected up-crossings of ``z`` (the Rice
formula for a chi-square process, Davies 1987, Biometrika 74, 33, in Baluev's finite-N
form: Baluev 2008, MNRAS 385, 1279, doi:10.1111/j.1365-2966.2008.12689.x, eq. 6 and
table 1, whose ``nu = 2`` case astropy's ``false_alarm_probability(method="baluev")``
computes). ``W = (f_max - f_min) sqrt(4 pi D_t) sqrt(mean k^2)``: the frequency band
times the effective baseline ``sqrt(4 pi D_t)`` (``D_t`` the weighted variance of the
epochs, averaged over the bands), times the root-mean-square harmonic order (the K-th
harmonic turns K times faster with ``f``; the mean of the components' rates bounds the
crossing rate from above, Jensen). ``nu = 2`` and ``B = 1`` give astropy's values (the
test checks it); for ``nu > 2`` a test checks it against the permutation bootstrap
(Suveges 2014, :mod:`.period_fap`).

**Coloured residuals.** A light curve that changes smoothly over a pass (range, phase
angle, airmass, the Earth's penumbra), left after the detrending, is not white noise: its
power piles up at low frequencies, and the white-noise FAP (and a bootstrap that shuffles
the epochs) calls it periodic. The peak's power is therefore divided by the noise level at
its frequency, ``g = max(1, mean_k R_k)``, before the formula: ``R_k`` the mean
Lomb-Scargle power of the detrended data (all bands pooled, each point divided by its
sigma) in the side bands ``1.5/span <= |f' - k f| <= 10/span`` of each harmonic ``k f``
(the other harmonics' own ``+-1.5/span`` left out) over its mean power from ``1/span`` to
the Nyquist frequency of the median spacing (the local noise level of a peak, Montgomery &
O'Donoghue 1999, DSSN 13, 28; a red-noise background, Vaughan 2005, A&A 431, 391,
doi:10.1051/0004-6361:20041453). White noise gives ``g ~ 1`` and the formula unchanged.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from speclight.estimate.period.periodogram import F64, BandSeries

#: Side bands of the local noise level, in units of ``1/span`` from each harmonic.
SIDE_INNER, SIDE_OUTER = 1.5, 10.0
#: Frequencies per side band.
SIDE_SAMPLES = 24


@dataclass
class AnalyticFap:
    """Everything the analytic false-alarm probability used (module docstring)."""

    n_points: int
    n_bands: int
    dof_signal: int
    bandwidth_hz: float
    baseline_s: float
    rms_order: float
    noise_level: float

    def fap(self, power: float) -> float:
        """False-alarm probability of a peak of ``power`` (before the noise level)."""
        return baluev_fap(
            power / self.noise_level, self.n_points - self.n_bands, self.dof_signal,
            self.bandwidth_hz * self.baseline_s * self.rms_order,
        )  # fmt: skip

    def power_at(self, fap: float) -> float:
        """The power whose false-alarm probability is ``fap`` (bisection)."""
        lo, hi = 0.0, 1.0
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if self.fap(mid) > fap else (lo, mid)
        return min(hi * self.noise_level, 1.0)


def baluev_fap(z: float, dof_null: int, dof_signal: int, w: float) -> float:
    """``FAP(z)`` of the module docstring.

    Parameters
    ----------
    z
        The power, the fraction of the chi-square explained, in [0, 1].
    dof_null
        ``N_H``, the points less the null model's parameters.
    dof_signal
        ``nu``, the parameters the periodic model adds.
    w
        ``W``, the frequency band times the effective baseline [1].
    """
    from scipy.special import betainc, gammaln

    nu, nh = float(dof_signal), float(dof_null)
    if nh - nu < 2:
        return float("nan")
    z = float(np.clip(z, 0.0, 1.0))
    if z >= 1.0:
        return 0.0
    single = float(betainc((nh - nu) / 2, nu / 2, 1.0 - z))
    if z <= 0.0:
        return 1.0
    log_tau = (
        np.log(w)
        + (nu - 1) / 2 * np.log(z)
        + (nh - nu - 1) / 2 * np.log1p(-z)
        + gammaln(nh / 2)
        - gammaln((nh - nu + 1) / 2)
        - gammaln(nu / 2)
    )
    tau = float(np.exp(min(log_tau, 700.0)))
    return float(min(-np.expm1(-tau) + single * np.exp(-tau), 1.0))


def _weighted_time_variance(series: BandSeries) -> float:
    """``D_t``: the weighted variance of the epochs per band (weights ``1/dy^2``), averaged
    over the bands with their point counts [s^2]."""
    total, count = 0.0, 0
    for b in range(series.n_bands):
        m = series.band == b
        if m.sum() < 2:
            continue
        w = 1.0 / series.dy[m] ** 2
        t = series.t_s[m]
        mean = np.sum(w * t) / np.sum(w)
        total += m.sum() * float(np.sum(w * (t - mean) ** 2) / np.sum(w))
        count += int(m.sum())
    return total / max(count, 1)


def local_noise_level(series: BandSeries, frequency_hz: float, harmonics: int) -> float:
    """``g``, the noise level beside the harmonics of ``frequency_hz`` over the mean level
    (module docstring), at least 1."""
    from astropy.timeseries import LombScargle

    span = series.span_s
    dt = float(np.median(np.diff(np.unique(series.t_s))))
    nyquist = 0.5 / dt
    r = np.zeros(series.y.size)
    for b in range(series.n_bands):
        m = series.band == b
        w = 1.0 / series.dy[m] ** 2
        r[m] = (series.y[m] - np.sum(w * series.y[m]) / np.sum(w)) / series.dy[m]
    ls = LombScargle(series.t_s, r, fit_mean=True, center_data=True)
    broad = np.linspace(1.0 / span, nyquist, 2000)
    level = float(np.mean(ls.power(broad, method="fast")))
    if not level > 0:
        return 1.0
    side = np.linspace(SIDE_INNER, SIDE_OUTER, SIDE_SAMPLES) / span
    side = np.concatenate([side, -side])
    centres = frequency_hz * np.arange(1, 2 * harmonics + 1)
    ratios = []
    for k in range(1, harmonics + 1):
        near = k * frequency_hz + side
        clear = np.all(np.abs(near[:, None] - centres[None, :]) >= SIDE_INNER / span, axis=1)
        near = near[clear & (near > 0.5 / span) & (near < nyquist)]
        if near.size:
            ratios.append(float(np.mean(ls.power(near, method="cython"))) / level)
    return max(float(np.mean(ratios)) if ratios else 1.0, 1.0)


def analytic_fap(
    series: BandSeries, frequency_hz: F64, harmonics: int, peak_frequency_hz: float
) -> AnalyticFap:
    """The analytic false-alarm probability of the peak at ``peak_frequency_hz`` on the
    grid ``frequency_hz`` (module docstring).

    Parameters
    ----------
    series
        The detrended light curves.
    frequency_hz
        The frequency grid searched [Hz].
    harmonics
        Harmonics ``K`` of the periodogram's model.
    peak_frequency_hz
        The peak whose noise level is measured [Hz].
    """
    counts = np.bincount(series.band, minlength=series.n_bands)
    used = counts > 2 * harmonics + 1
    n_bands = int(np.sum(used))
    orders = np.arange(1, harmonics + 1, dtype=float)
    return AnalyticFap(
        n_points=int(np.sum(counts[used])),
        n_bands=n_bands,
        dof_signal=2 * harmonics * n_bands,
        bandwidth_hz=float(frequency_hz[-1] - frequency_hz[0]),
        baseline_s=float(np.sqrt(4 * np.pi * _weighted_time_variance(series))),
        rms_order=float(np.sqrt(np.mean(orders**2))),
        noise_level=local_noise_level(series, peak_frequency_hz, harmonics),
    )
