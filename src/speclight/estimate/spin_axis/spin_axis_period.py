"""The sidereal rotation period of every candidate axis from a light curve's (synodic) period.

A light curve repeats when the body has turned once relative to the illumination and
viewing geometry, represented by the phase vector (the phase-angle bisector, PAB). If the
PAB turns about the spin axis at the mean rate ``Omega`` [rad/s] (right-handed), the light
curve's frequency is ``f_syn = f_sid - Omega / (2 pi)``, so

``P_sid = 1 / (1 / P_syn + Omega / (2 pi))``

(Harris et al. 1984, Icarus 57, 251, doi:10.1016/0019-1035(84)90140-1; Pravec et al. 2005,
Icarus 173, 108, doi:10.1016/j.icarus.2004.07.021; :mod:`speclight.estimate.period.synodic`
applies it for one known axis). ``speclight period`` measures ``P_syn``; during a low-orbit
pass the PAB turns by tens of degrees about most axes, so ``P_sid`` differs from ``P_syn``
by percents and by how much depends on the axis. The spin-axis search therefore takes,
for a synodic period (``period_kind = "synodic"``), each candidate axis's own sidereal period
(``Omega`` the least-squares slope of the PAB's unwrapped azimuth about it over the epochs):
the period and the axis are fitted together, and the refinement keeps them consistent
(:func:`.spin_axis_core.spin_axis_search`). ``"auto"`` tries the period as sidereal and as
synodic and keeps the interpretation whose best candidate fits better.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.estimate.spin_axis.spin_axis_lookup import EpochGeometry, axis_frames
from speclight.maps.map_geometry import map_coordinates

F64 = NDArray[np.float64]
#: How the given period is read: the body's period, the light curve's, or decided by the fit.
PERIOD_KINDS = ("sidereal", "synodic", "auto")
#: Axes per block of the rate computation (memory: block x epochs x 3 floats).
RATE_BLOCK = 2048


def check_period_kind(period_kind: str) -> None:
    """Refuse a period kind other than :data:`PERIOD_KINDS`."""
    if period_kind not in PERIOD_KINDS:
        raise InputError(
            f"period_kind = {period_kind!r}; accepted: {', '.join(PERIOD_KINDS)} (sidereal: "
            "the body's rotation period; synodic: the light curve's, as speclight period "
            "measures it; auto: the one that fits better)",
            field="period_kind",
        )


def bisector_rates(geo: EpochGeometry, ra_deg: F64, dec_deg: F64) -> F64:
    """Mean rate ``Omega`` [rad/s] (A,) of the phase vector's azimuth about each axis.

    The least-squares slope against time of the unwrapped azimuth (right-handed about the
    axis) over the epochs with a phase vector; NaN where fewer than 2 epochs have one.

    Parameters
    ----------
    geo
        Sun and observer directions (GCRS) and times of the epochs.
    ra_deg, dec_deg
        The axes [deg] (A,), GCRS.
    """
    p, _, _ = map_coordinates(geo.sun_gcrs, geo.observer_gcrs)
    ok = np.all(np.isfinite(p), axis=1)
    ra = np.atleast_1d(np.asarray(ra_deg, dtype=float))
    dec = np.atleast_1d(np.asarray(dec_deg, dtype=float))
    out = np.full(ra.size, np.nan)
    if ok.sum() < 2:
        return out
    p, t = p[ok], geo.t_s[ok]
    tc = t - t.mean()
    denom = float(np.sum(tc * tc))
    for a0 in range(0, ra.size, RATE_BLOCK):
        sl = slice(a0, a0 + RATE_BLOCK)
        v = np.matmul(p[None], axis_frames(ra[sl], dec[sl]))  # (A, T, 3) in each spin frame
        az = np.unwrap(np.arctan2(v[..., 1], v[..., 0]), axis=1)
        out[sl] = (az @ tc) / denom if denom > 0 else np.nan
    return out


def sidereal_periods(synodic_period_s: float, rates_rad_s: F64) -> F64:
    """``P_sid = 1 / (1 / P_syn + Omega / (2 pi))`` [s] (A,); NaN where that is not > 0
    (the bisector turning faster than the light curve's frequency) or ``Omega`` is NaN.

    Parameters
    ----------
    synodic_period_s
        The light curve's period [s].
    rates_rad_s
        ``Omega`` per axis [rad/s] (:func:`bisector_rates`).
    """
    freq = 1.0 / synodic_period_s + np.asarray(rates_rad_s, dtype=float) / (2 * np.pi)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(freq > 0, 1.0 / freq, np.nan)


def axis_sidereal_period(
    geo: EpochGeometry, synodic_period_s: float, ra_deg: float, dec_deg: float
) -> float:
    """The sidereal period [s] of one axis [deg] for the synodic period [s]."""
    rate = bisector_rates(geo, np.array([ra_deg]), np.array([dec_deg]))
    return float(sidereal_periods(synodic_period_s, rate)[0])
