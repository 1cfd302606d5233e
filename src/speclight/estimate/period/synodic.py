"""Synodic and sidereal rotation periods: the phase-angle bisector turns during a pass.

A light curve repeats when the body has turned once *relative to the illumination and
viewing geometry*, usually represented by the phase-angle bisector (PAB), the unit bisector
of the target-to-Sun and target-to-observer directions. If the PAB turns about the spin axis
at the angular rate ``Omega`` [rad/s] (right-handed), the body-frame azimuth of the PAB
changes at ``Omega - omega`` and the observed (synodic) frequency is
``f_syn = f_sid - Omega / (2 pi)``, so

``P_sid = 1 / (1 / P_syn + Omega / (2 pi))``  (about ``P_syn + Omega P^2 / (2 pi)``),

the synodic-sidereal relation of asteroid photometry (Harris et al. 1984, Icarus 57, 251,
doi:10.1016/0019-1035(84)90140-1; Pravec et al. 2005, Icarus 173, 108,
doi:10.1016/j.icarus.2004.07.021), with ``Omega`` the mean rate.

During a satellite pass the PAB turns far from uniformly (fastest near culmination), and a
periodogram weighs the stretches where the light curve varies most: the linear relation with
the mean rate can then be worse than no correction. So the relation is applied in its
differential form: the light curve is fitted with the rotation phase ``2 pi f t - phi(t)``,
``phi`` the PAB's unwrapped azimuth about the spin axis (right-handed) at each epoch, on a
frequency grid around ``1/P_syn`` (reaching 1.5 times the mean-rate shift, at least one peak
width), refined as the periodogram peak is, with the model the light curve needs in the
bisector's frame (:func:`.peak_refinement.refine_with_model`: harmonics from ``2K`` of the
rotation frequency, the trend's degree and the amplitude change chosen by F-tests; with the
periodogram's fixed ``1..2K`` and a cubic the sidereal period's sigma was 2x too wide and
its bias 2.4 times its scatter on a light curve with 4 harmonics and an amplitude change,
bench/bench_period_synodic_model.py). The sidereal period of this fit replaces the synodic
one only when asked (``apply``; ``speclight period --synodic bisector``) and when its
chi-square is lower than the plain fit's (same model, so the same number of parameters),
i.e. when the light curve does follow the bisector. It is not applied by default: on the
built-in box-wing pass (spin axis passing within 15 deg of the observer) the light curve
follows the Sun's fixed direction more than the bisector, and the correction moves a
period found within 0.6 % of the truth 2-6 % away from it (docs/period.md). ``Omega``
(weighted least-squares slope of ``phi`` against time, weights ``sum_b 1/sigma^2`` per
epoch) and the linear relation's period are reported for comparison. Without a known spin
axis the correction is bounded by the PAB's angular speed on the sky, ``|Omega| <=
|dPAB/dt|``: ``|P_sid - P_syn| <= P^2 |dPAB/dt| / (2 pi)`` (first order), reported instead.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from speclight.estimate.period.peak_refinement import refine_peak, refine_with_model
from speclight.estimate.period.periodogram import (
    F64,
    TREND_DEGREE,
    BandSeries,
    harmonic_chi2,
)


def _unit(v: F64) -> F64:
    return np.asarray(v / np.linalg.norm(v, axis=-1, keepdims=True), dtype=np.float64)


def bisector_angular_speed(t_s: F64, pab_gcrs: F64, weight: F64) -> float:
    """Weighted mean angular speed of the PAB on the sky [rad/s]."""
    p = _unit(pab_gcrs)
    step = np.arccos(np.clip(np.sum(p[1:] * p[:-1], axis=1), -1.0, 1.0)) / np.diff(t_s)
    w = 0.5 * (weight[1:] + weight[:-1])
    return float(np.sum(w * step) / np.sum(w))


def _weighted_slope(t: F64, y: F64, w: F64) -> float:
    tm = np.sum(w * t) / np.sum(w)
    ym = np.sum(w * y) / np.sum(w)
    return float(np.sum(w * (t - tm) * (y - ym)) / np.sum(w * (t - tm) ** 2))


@dataclass
class SynodicCorrection:
    """The sidereal rotation period from the synodic one (module docstring).

    Attributes
    ----------
    synodic_period_s
        The rotation period the light curve shows [s].
    sidereal_period_s, sidereal_std_s
        The period of the bisector-phase fit and its standard deviation [s], where it is
        applied (asked for, and fitting better than the plain fit); else None.
    bisector_fit_period_s
        The period of the bisector-phase fit, applied or not [s].
    linear_period_s
        ``1 / (1/P_syn + Omega/(2 pi))`` with the mean rate ``Omega``, for comparison.
    bisector_rate_rad_s
        ``Omega``, the weighted mean rate of the PAB's azimuth about the spin axis [rad/s].
    chi2_plain, chi2_bisector
        Chi-square of the best plain and bisector-phase fits.
    bound_s
        ``P^2 |dPAB/dt| / (2 pi)``, the size of the correction when the axis is unknown [s].
    method
        How the correction was made, in words.
    """

    synodic_period_s: float
    sidereal_period_s: float | None
    sidereal_std_s: float | None
    bisector_fit_period_s: float | None
    linear_period_s: float | None
    bisector_rate_rad_s: float | None
    chi2_plain: float | None
    chi2_bisector: float | None
    bound_s: float
    method: str

    @property
    def applied(self) -> bool:
        """Whether the sidereal period replaces the synodic one."""
        return self.sidereal_period_s is not None

    @property
    def correction_s(self) -> float | None:
        """``P_sid - P_syn`` where applied [s]."""
        if self.sidereal_period_s is None:
            return None
        return self.sidereal_period_s - self.synodic_period_s


def bisector_azimuth(pab_gcrs: F64, axis_gcrs: F64) -> F64:
    """Unwrapped azimuth of the PAB about ``axis_gcrs`` [rad], right-handed, (N,)."""
    axis = _unit(np.asarray(axis_gcrs, dtype=np.float64))
    ref = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = _unit(np.cross(axis, ref))
    e2 = np.cross(axis, e1)
    return np.asarray(np.unwrap(np.arctan2(pab_gcrs @ e2, pab_gcrs @ e1)), dtype=np.float64)


def sidereal_period(
    series: BandSeries,
    synodic_period_s: float,
    harmonics: int,
    t_s: F64,
    pab_gcrs: F64,
    weight: F64,
    axis_gcrs: F64 | None,
    apply: bool = True,
    not_applied_why: str = "not asked for (--synodic bisector applies it)",
    choose_model: bool = True,
) -> SynodicCorrection:
    """The sidereal period by the bisector-phase fit (module docstring); without an axis,
    only the bound.

    Parameters
    ----------
    series
        The light curves.
    synodic_period_s
        The period found by the periodogram [s].
    harmonics
        Harmonics of the model.
    t_s
        Epochs of the geometry [s], on the time axis of ``series``.
    pab_gcrs
        The phase-angle bisector at every epoch (N, 3), GCRS unit vectors.
    weight
        Weight of every epoch in the bisector's mean rate (N,).
    axis_gcrs
        The spin axis (3,), GCRS unit vector, or None (unknown: only the bound).
    apply
        Apply the fit to the period (``False``: reported, not applied).
    not_applied_why
        Why it is not applied, written into the correction's ``method``.
    choose_model
        Choose the fits' model in the bisector's frame
        (:func:`.peak_refinement.refine_with_model` from harmonics ``1..2K`` of the rotation
        frequency and a cubic; the plain fit then takes the same model); ``False``: both
        keep ``1..2K`` and a cubic (for comparison, bench/bench_period_synodic_model.py).
    """
    speed = bisector_angular_speed(t_s, pab_gcrs, weight)
    bound = float(synodic_period_s**2 * speed / (2 * np.pi))
    if axis_gcrs is None:
        text = (
            "spin axis unknown: no correction; bound P^2 |dPAB/dt| / (2 pi) with |dPAB/dt| = "
            f"{speed:.4g} rad/s, the weighted mean angular speed of the phase-angle bisector"
        )
        return SynodicCorrection(
            synodic_period_s, None, None, None, None, None, None, None, bound, text
        )
    phi = bisector_azimuth(pab_gcrs, axis_gcrs)
    rate = _weighted_slope(t_s, phi, weight)
    linear = 1.0 / (1.0 / synodic_period_s + rate / (2 * np.pi))
    phase = np.interp(series.t_s, t_s, phi)
    orders = list(range(1, 2 * harmonics + 1))
    f_syn = 1.0 / synodic_period_s
    reach = max(1.5 * abs(rate) / (2 * np.pi), 1.0 / series.span_s)
    grid = np.arange(f_syn - reach, f_syn + reach, 0.1 / series.span_s)
    grid = grid[grid > 0]
    chi = [harmonic_chi2(series, f, orders, phase, TREND_DEGREE)[0] for f in grid]
    start = float(grid[int(np.argmin(chi))])
    if choose_model:
        fitted = refine_with_model(series, start, 2 * harmonics, phase_rad=phase)
        orders = fitted.orders
    else:
        fitted = refine_peak(series, start, orders, phase)
    degree, change = fitted.trend_degree, fitted.amplitude_change
    plain = refine_peak(series, f_syn, orders, trend_degree=degree, amplitude_change=change)
    common = (
        f"Omega = {rate:.4g} rad/s (weighted mean rate of the phase-angle bisector's azimuth "
        f"about the spin axis; linear relation P_sid = 1/(1/P_syn + Omega/(2 pi)) = "
        f"{linear:.6g} s, Harris et al. 1984, Pravec et al. 2005)"
    )
    p_fit = 1.0 / fitted.frequency_hz
    if apply and fitted.chi2 < plain.chi2:
        return SynodicCorrection(
            synodic_period_s,
            p_fit,
            fitted.frequency_std_hz * p_fit**2,
            p_fit,
            linear,
            rate,
            plain.chi2,
            fitted.chi2,
            bound,
            "sidereal period from the fit in the bisector's frame (rotation phase "
            f"2 pi f t - azimuth of the bisector), chi2 {fitted.chi2:.6g} < plain "
            f"{plain.chi2:.6g}; {common}",
        )
    why = (
        not_applied_why
        if not apply
        else f"it fits worse than the plain fit (chi2 {plain.chi2:.6g})"
    )
    return SynodicCorrection(
        synodic_period_s,
        None,
        None,
        p_fit,
        linear,
        rate,
        plain.chi2,
        fitted.chi2,
        bound,
        f"not applied, {why}: the fit in the bisector's frame gives {p_fit:.6g} s (chi2 "
        f"{fitted.chi2:.6g}); {common}",
    )
