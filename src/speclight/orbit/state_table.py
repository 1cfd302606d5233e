"""Shared machinery of the OEM and SP3 readers: time scales, Hermite interpolation, segments.

A *segment* is a table of epochs, positions (and velocities) in one frame and one time
scale, valid over a closed interval; interpolation windows never cross a segment's ends (a
new segment usually follows a manoeuvre). Epochs outside every segment are not valid: no
extrapolation.

Time scales: table epochs are calendar times in the file's scale; they are turned into TAI
(``TAI - UTC`` from skyfield's leap-second table; fixed offsets for the others: TT = TAI +
32.184 s, GPS = TAI - 19 s (IS-GPS-200), BeiDou BDT = TAI - 33 s, GLONASS time = UTC + 3 h)
and interpolation runs in TAI seconds, so it is exact across leap seconds.

Frames (rotated to the GCRS at each query epoch, after interpolation in the file's frame):

* ``GCRF``, ``ICRF``: the GCRS axes (the GCRS is the geocentric frame aligned with the ICRS).
* ``EME2000`` / ``J2000``: the mean equator and equinox of J2000.0 differ from the ICRS by the
  constant frame bias (IERS Conventions 2010, sec. 5.4.4: d_alpha0 = -14.6 mas, xi0 = -16.617
  mas, eta0 = -6.819 mas, about 23 mas in all); it is applied (skyfield's ``ICRS_to_J2000``
  matrix) although it is only ~0.8 m at LEO and ~5 m at GEO distance.
* ``ITRF`` and its realisations (``ITRF2000``, ``ITRF-93``, ``ITRF2014``, ``IGS14``...):
  skyfield's ITRS -> GCRS (with polar motion); the realisations differ by centimetres,
  which is ignored.
* ``TEME``: SGP4's true-equator mean-equinox frame (skyfield's definition).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from skyfield.framelib import ICRS_to_J2000

from speclight.orbit.frames import EarthOrientation, TimeLike, as_time, earth_orientation
from speclight.orbit.interpolate import lagrange_interpolate, lagrange_window
from speclight.orbit.timescale import time_from_utc

#: Time scales as their constant offset to TAI [s] (``TAI = t + offset``); UTC and GLONASS
#: time follow the leap seconds and are handled apart.
TAI_MINUS = {"TAI": 0.0, "TT": -32.184, "GPS": 19.0, "BDT": 33.0}
UTC_LIKE = {"UTC": 0.0, "GLO": -3 * 3600.0}  # UTC = t + offset
#: Frame names accepted, by the treatment they get.
INERTIAL_FRAMES = ("GCRF", "ICRF")
EME2000_FRAMES = ("EME2000", "J2000")
TEME_FRAMES = ("TEME",)
J2000_EPOCH = np.datetime64("2000-01-01T12:00:00", "ns")
#: Span of ``datetime64[ns]``; numpy wraps times beyond it around silently.
TIME_RANGE = (np.datetime64("1678-01-01T00:00:00", "s"), np.datetime64("2262-01-01T00:00:00", "s"))


def as_ns(t: np.datetime64) -> np.datetime64:
    """A parsed time as ``datetime64[ns]``; ValueError outside 1678-2262 (numpy would wrap)."""
    if np.isnat(t):
        raise ValueError("not a time")
    if not TIME_RANGE[0] <= t < TIME_RANGE[1]:
        raise ValueError("the time is outside 1678-2262")
    return t.astype("datetime64[ns]")


def frame_kind(name: str) -> str | None:
    """``"gcrs"``, ``"eme2000"``, ``"itrs"`` or ``"teme"`` for an accepted frame name, else None."""
    n = name.strip().upper()
    if n in INERTIAL_FRAMES:
        return "gcrs"
    if n in EME2000_FRAMES:
        return "eme2000"
    if n in TEME_FRAMES:
        return "teme"
    if n.startswith(("ITRF", "ITRS", "IGS", "IGB")):
        return "itrs"
    return None


def tai_julian(times: NDArray[np.datetime64], scale: str) -> tuple[NDArray[np.float64], ...]:
    """Calendar times in ``scale`` as a TAI Julian date split ``(whole, fraction)``."""
    t64 = np.asarray(times, dtype="datetime64[ns]")
    if scale in UTC_LIKE:
        utc = t64 + np.timedelta64(int(UTC_LIKE[scale] * 1e9), "ns")
        t = time_from_utc(utc.astype("datetime64[ns]"))
        return np.asarray(t.whole, dtype=np.float64), np.asarray(t.tai_fraction, dtype=np.float64)
    ns = (t64 - J2000_EPOCH).astype(np.int64) + round(TAI_MINUS[scale] * 1e9)
    day_ns = 86_400_000_000_000
    days = np.floor_divide(ns, day_ns)
    return 2451545.0 + days.astype(np.float64), (ns - days * day_ns).astype(np.float64) / day_ns


def hermite_interpolate(
    x_nodes: NDArray[np.float64],
    y_nodes: NDArray[np.float64],
    dy_nodes: NDArray[np.float64],
    x: NDArray[np.float64],
    n_points: int,
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Hermite interpolation from values and first derivatives on a sliding window.

    With ``n`` nodes the polynomial has degree ``2n - 1`` and matches value and derivative at
    every node: ``H(x) = sum_j L_j(x)^2 [(1 - 2 L_j'(x_j)(x - x_j)) y_j + (x - x_j) y'_j]``,
    ``L_j`` the Lagrange basis, ``L_j'(x_j) = sum_{k != j} 1 / (x_j - x_k)`` (e.g. Burden &
    Faires, *Numerical Analysis*, Theorem 3.9). Shapes: nodes (M,), values (M, K), queries
    (N,); the window (``n`` nodes, reduced to M) is centred on each query as in
    :func:`~speclight.orbit.interpolate.lagrange_interpolate`; NaN outside the nodes' span.
    """
    xn = np.asarray(x_nodes, dtype=np.float64)
    m = xn.size
    n = min(int(n_points), m)
    xq = np.atleast_1d(np.asarray(x, dtype=np.float64))
    ok, idx, dx, basis, slope = lagrange_window(xn, xq, n)
    basis2 = basis**2  # L_j(x)^2
    a = basis2 * (1.0 - 2.0 * slope * dx)
    b = basis2 * dx
    yn = np.asarray(y_nodes, dtype=np.float64)
    dyn = np.asarray(dy_nodes, dtype=np.float64)
    y = np.zeros((xq.size, yn.shape[1]))
    for j in range(n):
        y += a[:, j, None] * yn[idx[:, j]] + b[:, j, None] * dyn[idx[:, j]]
    y[~ok] = np.nan
    return y, ok


@dataclass(frozen=True)
class Segment:
    """One interpolable table.

    Attributes
    ----------
    frame
        Frame kind, see :func:`frame_kind`.
    tai_whole, tai_fraction
        (M,) TAI Julian dates of the records, split.
    r_m, v_m_s
        (M, 3) positions [m] and velocities [m/s] (None: positions only).
    method
        ``"hermite"`` (needs velocities) or ``"lagrange"``.
    n_points
        Nodes per interpolation window.
    valid_tai
        ``(whole, first_fraction, last_fraction)``: the usable interval, as TAI Julian dates
        sharing one whole part.
    """

    frame: str
    tai_whole: NDArray[np.float64]
    tai_fraction: NDArray[np.float64]
    r_m: NDArray[np.float64]
    v_m_s: NDArray[np.float64] | None
    method: str
    n_points: int
    valid_tai: tuple[float, float, float]


def _seconds(whole: NDArray[np.float64], frac: NDArray[np.float64], w0: float) -> NDArray:
    return ((np.asarray(whole, dtype=np.float64) - w0) + np.asarray(frac)) * 86400.0


def _to_gcrs(frame: str, r: NDArray[np.float64], eo: EarthOrientation) -> NDArray[np.float64]:
    if frame == "gcrs":
        return r
    if frame == "eme2000":
        return r @ np.asarray(ICRS_to_J2000)  # r_gcrs = B^T r_j2000, row vectors
    if frame == "itrs":
        return eo.itrs_to_gcrs(r)
    return eo.teme_to_gcrs(r)


def segments_position_gcrs_m(
    segments: list[Segment], t: TimeLike, orientation: EarthOrientation | None = None
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """GCRS positions [m] (N, 3) at ``t`` and the ok mask: each epoch from the first segment
    whose usable interval covers it; NaN and False where none does."""
    t = as_time(t)
    qw = np.atleast_1d(np.asarray(t.whole, dtype=np.float64))
    qf = np.atleast_1d(np.asarray(t.tai_fraction, dtype=np.float64))
    out = np.full((qw.size, 3), np.nan)
    done = np.zeros(qw.size, dtype=bool)
    eo: EarthOrientation | None = orientation
    for seg in segments:
        w0 = seg.valid_tai[0]
        x = _seconds(qw, qf, w0)
        lo, hi = seg.valid_tai[1] * 86400.0, seg.valid_tai[2] * 86400.0
        take = ~done & (x >= lo) & (x <= hi)
        if not take.any():
            continue
        xn = _seconds(seg.tai_whole, seg.tai_fraction, w0)
        if seg.method == "hermite" and seg.v_m_s is not None:
            r, ok = hermite_interpolate(xn, seg.r_m, seg.v_m_s, x[take], seg.n_points)
        else:
            r, ok = lagrange_interpolate(xn, seg.r_m, x[take], seg.n_points)
        if seg.frame in ("itrs", "teme"):
            if eo is None:
                eo = earth_orientation(t)
            sub = EarthOrientation(eo.gcrs_to_itrs[take], eo.gcrs_to_teme[take])
        else:
            sub = EarthOrientation(np.empty((0, 3, 3)), np.empty((0, 3, 3)))
        out[take] = _to_gcrs(seg.frame, r, sub)
        done[np.flatnonzero(take)[ok]] = True
    ok_all = done & np.all(np.isfinite(out), axis=1)
    out[~ok_all] = np.nan
    return out, ok_all
