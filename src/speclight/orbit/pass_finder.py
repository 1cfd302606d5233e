"""Passes of a target over a site: rise, culmination and set, and the parts of each pass in
which the target is sunlit, the sky is dark, and both (observable).

The search follows skyfield's ``EarthSatellite.find_events`` (Rhodes, skyfield
``sgp4lib.py``): sample the elevation on a grid, refine every local maximum (a pass shorter
than the grid step still shows as one), and find each crossing of the minimum elevation
between two samples by bisection. Here the samples come from a function of the epochs, so
one search serves every orbit source (TLE, CPF, OEM, SP3, tables) with the pipeline's own
geometry (light time, refraction, the conical shadow). The sunlit (``sunlit_fraction > 0``,
penumbra included) and dark-sky (Sun at or below ``max_sun_elevation_deg``) limits inside a
pass are found the same way. Events are located to ``tolerance_s``; an excursion shorter
than the grid step that does not change the elevation's maxima (a brief shadow crossing) can
be missed.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]
#: A time interval (start, end), UTC.
Interval = tuple[np.datetime64, np.datetime64]


@dataclass(frozen=True)
class PassSamples:
    """What the search needs at a set of epochs, each of shape (N,).

    Attributes
    ----------
    elevation_deg, azimuth_deg, range_m
        Topocentric target position [deg, deg, m]; NaN where the orbit gives none.
    sun_elevation_deg
        The Sun's elevation at the site [deg].
    sunlit_fraction
        Fraction of the solar disk seen from the target [1].
    """

    elevation_deg: F64
    azimuth_deg: F64
    range_m: F64
    sun_elevation_deg: F64
    sunlit_fraction: F64


#: ``sample(time_utc) -> PassSamples`` for UTC ``datetime64[ns]`` epochs (N,).
Sampler = Callable[[NDArray[np.datetime64]], PassSamples]


@dataclass(frozen=True)
class Pass:
    """One pass of the target above the minimum elevation (within the search window).

    Attributes
    ----------
    rise_utc, culmination_utc, set_utc
        Crossing of the minimum elevation upward, highest elevation, crossing downward
        (the window's start or end where the target is already up or still up then).
    rise_azimuth_deg, culmination_azimuth_deg, set_azimuth_deg
        Azimuth at those epochs [deg].
    max_elevation_deg
        Elevation at culmination [deg].
    culmination_range_m
        Range at culmination [m].
    rises_before_start, sets_after_end
        Whether the pass is cut by the window's start or end.
    sunlit, dark_sky, observable
        Parts of the pass with the target sunlit, the Sun at or below the dark-sky limit,
        and both.
    """

    rise_utc: np.datetime64
    culmination_utc: np.datetime64
    set_utc: np.datetime64
    rise_azimuth_deg: float
    culmination_azimuth_deg: float
    set_azimuth_deg: float
    max_elevation_deg: float
    culmination_range_m: float
    rises_before_start: bool
    sets_after_end: bool
    sunlit: tuple[Interval, ...]
    dark_sky: tuple[Interval, ...]
    observable: tuple[Interval, ...]

    @property
    def observable_s(self) -> float:
        """Total observable time in the pass [s]."""
        return float(sum((b - a) / np.timedelta64(1, "s") for a, b in self.observable))


def _bisect(test: Callable[[I64], NDArray[np.bool_]], lo: I64, hi: I64, tol_ns: int) -> I64:
    """Epochs [ns] where ``test`` changes value, one in each bracket ``[lo, hi]``.

    ``test(lo) != test(hi)`` in every bracket; halves all brackets together until they are
    shorter than ``tol_ns`` and returns their middles.
    """
    lo, hi = lo.copy(), hi.copy()
    if lo.size == 0:
        return lo
    at_lo = test(lo)
    while np.any(hi - lo > tol_ns):
        mid = lo + (hi - lo) // 2
        same = test(mid) == at_lo
        lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
    return lo + (hi - lo) // 2


def _runs(mask: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """(first, last) index of each run of True values."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1
    return list(zip(starts.tolist(), stops.tolist(), strict=True))


def _intersect(a: list[Interval], b: list[Interval]) -> list[Interval]:
    out = []
    for a0, a1 in a:
        for b0, b1 in b:
            lo, hi = max(a0, b0), min(a1, b1)
            if lo < hi:
                out.append((lo, hi))
    return out


class _Search:
    """The sampler on integer nanoseconds, with the elevation NaN-safe."""

    def __init__(self, sample: Sampler, min_elevation_deg: float, max_sun_elevation_deg: float):
        self.sample = sample
        self.min_el = min_elevation_deg
        self.max_sun = max_sun_elevation_deg

    def at(self, ns: I64) -> PassSamples:
        if ns.size == 0:
            none = np.zeros(0)
            return PassSamples(none, none, none, none, none)
        return self.sample(ns.astype("datetime64[ns]"))

    @staticmethod
    def height(s: PassSamples) -> F64:
        return np.where(np.isfinite(s.elevation_deg), s.elevation_deg, -np.inf)

    def above(self, ns: I64) -> NDArray[np.bool_]:
        return self.height(self.at(ns)) >= self.min_el

    def lit(self, s: PassSamples) -> NDArray[np.bool_]:
        return np.isfinite(s.elevation_deg) & (s.sunlit_fraction > 0.0)

    def dark(self, s: PassSamples) -> NDArray[np.bool_]:
        return s.sun_elevation_deg <= self.max_sun

    def rising(self, ns: I64, half_ns: int) -> NDArray[np.bool_]:
        h = self.height(self.at(np.concatenate([ns - half_ns, ns + half_ns])))
        return h[ns.size :] > h[: ns.size]


def _maxima(search: _Search, t: I64, h: F64, tol_ns: int) -> tuple[I64, F64]:
    """Refined local maxima of the elevation between grid samples: epochs and heights."""
    i = np.flatnonzero((h[1:-1] > h[:-2]) & (h[1:-1] >= h[2:]) & np.isfinite(h[1:-1])) + 1
    half_ns = max(tol_ns // 2, 1)
    t_max = _bisect(lambda ns: search.rising(ns, half_ns), t[i - 1], t[i + 1], tol_ns)
    return t_max, search.height(search.at(t_max))


def _limits(
    search: _Search,
    t: I64,
    values: NDArray[np.bool_],
    test: Callable[[I64], NDArray[np.bool_]],
    tol_ns: int,
) -> list[Interval]:
    """Intervals where ``values`` (sampled at ``t``, refined by ``test``) are True."""
    change = np.flatnonzero(values[1:] != values[:-1])
    cross = _bisect(test, t[change], t[change + 1], tol_ns)
    edges = dict(zip(change.tolist(), cross.tolist(), strict=True))
    out: list[Interval] = []
    for a, b in _runs(values):
        start = t[a] if a == 0 else edges[a - 1]
        end = t[b] if b == t.size - 1 else edges[b]
        if end > start:
            out.append((np.datetime64(int(start), "ns"), np.datetime64(int(end), "ns")))
    return out


def find_passes(
    sample: Sampler,
    start_utc: np.datetime64,
    end_utc: np.datetime64,
    min_elevation_deg: float,
    max_sun_elevation_deg: float,
    step_s: float = 60.0,
    tolerance_s: float = 1e-3,
) -> list[Pass]:
    """The passes of a target above ``min_elevation_deg`` between two UTC epochs.

    Parameters
    ----------
    sample
        ``sample(time_utc) -> PassSamples``: the geometry at given epochs.
    start_utc, end_utc
        The search window, UTC ``datetime64`` (end after start).
    min_elevation_deg
        Elevation of rise and set [deg].
    max_sun_elevation_deg
        Highest elevation of the Sun at the site for a dark sky [deg].
    step_s
        Grid step [s]: elevation maxima are found however short the pass; the sunlit and
        dark-sky limits need to be further apart than this.
    tolerance_s
        Accuracy of every event time [s].

    Returns
    -------
    list of Pass
        In time order.
    """
    search = _Search(sample, min_elevation_deg, max_sun_elevation_deg)
    t0 = int(np.asarray(start_utc, dtype="datetime64[ns]").astype(np.int64))
    t1 = int(np.asarray(end_utc, dtype="datetime64[ns]").astype(np.int64))
    step_ns, tol_ns = int(step_s * 1e9), max(int(tolerance_s * 1e9), 1)
    grid = np.unique(np.append(np.arange(t0, t1, step_ns, dtype=np.int64), t1))
    s = search.at(grid)
    h = search.height(s)
    t_max, h_max = _maxima(search, grid, h, tol_ns)
    # the grid and the refined maxima together: a pass between two samples shows there
    t = np.concatenate([grid, t_max])
    order = np.argsort(t, kind="stable")
    t, h = t[order], np.concatenate([h, h_max])[order]
    spans = _limits(search, t, h >= min_elevation_deg, search.above, tol_ns)
    passes = []
    for rise, set_ in spans:
        r, e = int(rise.astype(np.int64)), int(set_.astype(np.int64))
        times = np.concatenate([[r], t[(t > r) & (t < e)], [e]])
        fine = search.at(times)  # the pass's samples, the refined maxima among them
        k = int(np.argmax(search.height(fine)))
        lit = _limits(search, times, search.lit(fine), lambda n: search.lit(search.at(n)), tol_ns)
        dark = _limits(
            search, times, search.dark(fine), lambda n: search.dark(search.at(n)), tol_ns
        )
        passes.append(
            Pass(
                rise_utc=rise,
                culmination_utc=np.datetime64(int(times[k]), "ns"),
                set_utc=set_,
                rise_azimuth_deg=float(fine.azimuth_deg[0]),
                culmination_azimuth_deg=float(fine.azimuth_deg[k]),
                set_azimuth_deg=float(fine.azimuth_deg[-1]),
                max_elevation_deg=float(fine.elevation_deg[k]),
                culmination_range_m=float(fine.range_m[k]),
                rises_before_start=r == t0,
                sets_after_end=e == t1,
                sunlit=tuple(lit),
                dark_sky=tuple(dark),
                observable=tuple(_intersect(lit, dark)),
            )
        )
    return passes
