"""Light curves in, detrended magnitudes out (step 1 of ``speclight period``).

The count rates of the chosen bands become magnitudes ``-2.5 log10(rate)`` with
``sigma_mag = 2.5 / ln 10 * sigma / rate`` (the measured sigmas, else the shot noise
``sqrt(rate / t)`` with ``t`` the scenario's exposure or the median epoch spacing); points
with ``rate <= 2 sigma`` are left out. The light curve is cut into passes at gaps longer
than :data:`PASS_GAP_S` (a satellite is seen for minutes per pass, passes are an orbit or
more apart), and a weighted polynomial in time (degree :data:`DETREND_DEGREE`) is
subtracted per band and pass: the slow change of range, phase angle and airmass over each
pass.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.estimate.inputs.measured import MeasuredLightCurve
from speclight.estimate.period.periodogram import F64, BandSeries

#: Polynomial degree of the trend removed per band and pass.
DETREND_DEGREE = 3
#: A gap longer than this starts a new pass [s]: 30 min, a third of the shortest orbit
#: (a low orbit's pass lasts at most ~15 min; the next is ~90 min later).
PASS_GAP_S = 1800.0
LN10 = float(np.log(10.0))
#: Smallest magnitude sigma accepted [mag]: one part per million, far below what any
#: photometry reaches (scintillation alone is ~1e-3 mag in 1 s). A smaller sigma (a sigma
#: column of ~0, or a rate so huge that its shot noise vanishes) would weigh ``1/sigma^2``
#: over every other epoch together, or overflow.
MIN_SIGMA_MAG = 1e-6
#: Brightest rate accepted, as a factor over its band's median usable rate: 1e6, 15 mag.
#: Glints of flat panels reach 8-10 mag above a satellite's diffuse level; a rate a million
#: times the median is a broken value, and it alone would set the periodogram.
MAX_RATE_OVER_MEDIAN = 1e6


def pass_index(t_s: F64) -> NDArray[np.int64]:
    """The pass of each epoch (0, 1, ...): a new pass after each gap > :data:`PASS_GAP_S`."""
    gaps = np.diff(t_s) > PASS_GAP_S
    return np.concatenate([[0], np.cumsum(gaps)]).astype(np.int64)


def _detrend(t_s: F64, mag: F64, dmag: F64, ok: NDArray[np.bool_]) -> None:
    """Subtract, in place, the weighted polynomial trend of each band and pass."""
    passes = pass_index(t_s)
    for p in range(int(passes[-1]) + 1):
        inside = passes == p
        t_p = t_s[inside]
        span = max(float(t_p[-1] - t_p[0]), 1e-9)
        for b in range(mag.shape[1]):
            m = inside & ok[:, b]
            if m.sum() > DETREND_DEGREE + 1:
                x = (t_s[m] - t_p[0]) / span
                c = np.polynomial.polynomial.polyfit(x, mag[m, b], DETREND_DEGREE, w=1 / dmag[m, b])
                mag[m, b] -= np.polynomial.polynomial.polyval(x, c)


def magnitude_series(
    lc: MeasuredLightCurve, exposure_s: float | None = None
) -> tuple[BandSeries, F64, F64]:
    """Detrended magnitudes of all bands (module docstring, step 1).

    Returns
    -------
    series
        The finite points, flattened.
    t_s
        (N,) time of each epoch since the first [s].
    weight
        (N,) information of each epoch, ``sum_b 1/sigma_mag^2`` (0 where none is usable).
    """
    t_s = (lc.time_utc - lc.time_utc[0]) / np.timedelta64(1, "s")
    rate = lc.rate_per_s
    if lc.sigma_per_s is not None:
        sigma = lc.sigma_per_s
    else:
        t_exp = exposure_s if exposure_s else float(np.median(np.diff(t_s)))
        sigma = np.sqrt(np.abs(rate) / (t_exp * lc.n_samples[:, None]))
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        ok = np.isfinite(rate) & np.isfinite(sigma) & (sigma > 0) & (rate > 2 * sigma)
        mag = np.where(ok, -2.5 * np.log10(np.where(ok, rate, 1.0)), np.nan)
        dmag = np.where(ok, 2.5 / LN10 * sigma / np.where(ok, rate, 1.0), np.nan)
    _check_usable_points(lc, ok, dmag)
    _detrend(t_s, mag, dmag, ok)
    tt = np.broadcast_to(t_s[:, None], rate.shape)
    bb = np.broadcast_to(np.arange(rate.shape[1])[None, :], rate.shape)
    series = BandSeries(
        t_s=tt[ok].astype(float),
        y=mag[ok],
        dy=dmag[ok],
        band=bb[ok].astype(np.int64),
        n_bands=rate.shape[1],
    )
    weight = np.where(ok, 1.0 / np.where(ok, dmag, 1.0) ** 2, 0.0).sum(axis=1)
    return series, t_s, weight


def _check_usable_points(lc: MeasuredLightCurve, ok: NDArray[np.bool_], dmag: F64) -> None:
    """Refuse a usable rate far above its band's median (:data:`MAX_RATE_OVER_MEDIAN`) or
    with a sigma below :data:`MIN_SIGMA_MAG`, naming the first such point."""
    rate = lc.rate_per_s
    for b, name in enumerate(lc.band_names):
        m = ok[:, b]
        if not m.any():
            continue
        median = float(np.median(rate[m, b]))
        bright = np.flatnonzero(m & (rate[:, b] > MAX_RATE_OVER_MEDIAN * median))
        if bright.size:
            i = int(bright[0])
            raise InputError(
                f"band '{name}' at {lc.time_utc[i]}: rate {rate[i, b]:.3g} s-1 is "
                f"{rate[i, b] / median:.3g} times the band's median {median:.3g} s-1 "
                f"({bright.size} such epoch(s)); no light curve varies by more than "
                f"{MAX_RATE_OVER_MEDIAN:.0e} (15 mag): check the file",
                source=lc.source,
                field="MEASURED",
            )
        fine = np.flatnonzero(m & (dmag[:, b] < MIN_SIGMA_MAG))
        if fine.size:
            i = int(fine[0])
            sigma = dmag[i, b] * rate[i, b] * LN10 / 2.5
            raise InputError(
                f"band '{name}' at {lc.time_utc[i]}: sigma {sigma:.3g} s-1 of the rate "
                f"{rate[i, b]:.3g} s-1 is {dmag[i, b]:.3g} mag ({fine.size} such epoch(s)); "
                f"accepted: at least {MIN_SIGMA_MAG:g} mag (no photometry is more precise): "
                "check the sigma columns",
                source=lc.source,
                field="MEASURED",
            )
