"""A target placed where it was seen: site + azimuth, elevation, range (or height) -> GCRS.

The inverse of :func:`speclight.orbit.observer.topocentric` (same WGS84 site, same
geodetic east-north-up axes, same Earth orientation from skyfield), so a target placed
here and observed again by the pipeline gives back the azimuth, elevation and range it
was placed at. Elevations are geometric (no refraction is removed).

:func:`observed_trajectory` turns the placed positions into the ``t -> (r_gcrs_m, ok)``
callable the geometry stage takes in place of an orbit (``orbit: {observed: true}``).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.orbit.frames import TimeLike, earth_orientation
from speclight.orbit.observer import Site
from speclight.orbit.shadow import EARTH_EQUATORIAL_RADIUS_M, EARTH_POLAR_RADIUS_M
from speclight.orbit.timescale import time_from_utc

F64 = NDArray[np.float64]
_E2 = 1.0 - (EARTH_POLAR_RADIUS_M / EARTH_EQUATORIAL_RADIUS_M) ** 2
#: Bisection steps of the range that gives a height: the bracket 0..MAX_RANGE_M shrinks to
#: 1e8 m / 2^60 < 1e-9 m.
BISECTION_STEPS = 60
MAX_RANGE_M = 1e8
#: Gap between observed positions that the trajectory does not bridge [s]: one pass of a
#: LEO target is minutes long, and a target seen twice in 30 s moves on a near-straight
#: line (a 7.5 km/s orbit's chord of 30 s departs from the arc by < 1 km).
MAX_GAP_S = 30.0
#: How far from an observed position the trajectory still answers with it where it cannot
#: interpolate (an end of the table, or a gap) [s]: the light-time iteration first asks at
#: the reception time, ~0.01 s after the emission.
NEAR_S = 0.1


def line_of_sight_itrs(site: Site, azimuth_deg: F64, elevation_deg: F64) -> F64:
    """Unit vectors (N, 3) from the site toward azimuth/elevation, ITRS axes."""
    az, el = np.radians(azimuth_deg), np.radians(elevation_deg)
    enu = np.stack((np.cos(el) * np.sin(az), np.cos(el) * np.cos(az), np.sin(el)), axis=-1)
    return np.asarray(enu @ site.enu_matrix, dtype=np.float64)


def geodetic_height_m(r_itrs_m: F64) -> F64:
    """Height above the WGS84 ellipsoid of ITRS points (N, 3) [m].

    Geodetic latitude by fixed-point iteration of ``tan(phi) = (z + e^2 N sin phi) / p``
    (Hofmann-Wellenhof et al., *GNSS*, Springer 2008, sec. 10.2.1), then
    ``h = p / cos(phi) - N`` (or ``|z| - b`` near the poles).
    """
    x, y, z = r_itrs_m[:, 0], r_itrs_m[:, 1], r_itrs_m[:, 2]
    p = np.hypot(x, y)
    lat = np.arctan2(z, p * (1.0 - _E2))
    for _ in range(10):
        n = EARTH_EQUATORIAL_RADIUS_M / np.sqrt(1.0 - _E2 * np.sin(lat) ** 2)
        lat = np.arctan2(z + _E2 * n * np.sin(lat), p)
    n = EARTH_EQUATORIAL_RADIUS_M / np.sqrt(1.0 - _E2 * np.sin(lat) ** 2)
    cl = np.cos(lat)
    with np.errstate(divide="ignore", invalid="ignore"):
        h = np.where(np.abs(cl) > 1e-9, p / cl - n, np.abs(z) - n * (1.0 - _E2))
    return np.asarray(h, dtype=np.float64)


def range_from_height_m(site: Site, azimuth_deg: F64, elevation_deg: F64, height_m: F64) -> F64:
    """Range [m] along the line of sight at which the height above the ellipsoid is
    ``height_m``; NaN where the line of sight does not rise (elevation <= 0) or the height
    is not reached within :data:`MAX_RANGE_M`.

    For an elevation > 0 the height grows monotonically along the line of sight (it
    leaves the tangent plane upward), so bisection finds the one crossing.
    """
    u = line_of_sight_itrs(site, azimuth_deg, elevation_deg)
    o = site.position_itrs_m
    h = np.asarray(height_m, dtype=np.float64)
    lo = np.zeros(h.shape)
    hi = np.full(h.shape, MAX_RANGE_M)
    for _ in range(BISECTION_STEPS):
        mid = 0.5 * (lo + hi)
        above = geodetic_height_m(o + mid[:, None] * u) > h
        hi = np.where(above, mid, hi)
        lo = np.where(above, lo, mid)
    rng = 0.5 * (lo + hi)
    reached = geodetic_height_m(o + MAX_RANGE_M * u) > h
    ok = (np.asarray(elevation_deg) > 0) & reached & (h > site.altitude_m)
    return np.where(ok, rng, np.nan)


def place_target_gcrs_m(
    site: Site, t: TimeLike, azimuth_deg: F64, elevation_deg: F64, range_m: F64
) -> F64:
    """GCRS positions (N, 3) [m] of targets seen from ``site`` at epochs ``t`` (N)."""
    eo = earth_orientation(t)
    u = line_of_sight_itrs(site, azimuth_deg, elevation_deg)
    r_itrs = site.position_itrs_m + np.asarray(range_m, dtype=np.float64)[:, None] * u
    return eo.itrs_to_gcrs(r_itrs)


def tt_seconds(t: Any, ref_whole: float) -> F64:
    """Seconds of TT since the Julian date ``ref_whole`` (split JD keeps nanoseconds)."""
    whole = np.atleast_1d(np.asarray(t.whole, dtype=np.float64))
    frac = np.atleast_1d(np.asarray(t.tt_fraction, dtype=np.float64))
    return np.asarray((whole - ref_whole) * 86400.0 + frac * 86400.0, dtype=np.float64)


def position_table(
    emitted_utc: NDArray[np.datetime64], r_gcrs_m: F64, ref_whole: float | None = None
) -> tuple[F64, F64, float]:
    """The placed positions as a table for :func:`table_position`: TT seconds since
    ``ref_whole`` (sorted, unique; default: the first epoch's Julian date), positions
    (M, 3) [m] (rows with NaN dropped; of a repeated epoch the first kept) and ``ref_whole``."""
    keep = np.all(np.isfinite(r_gcrs_m), axis=1)
    order = np.argsort(emitted_utc[keep], kind="stable")
    t_tab = time_from_utc(np.asarray(emitted_utc[keep])[order])
    if ref_whole is None:
        ref_whole = float(np.atleast_1d(t_tab.whole)[0]) if keep.any() else 0.0
    s_tab, first = np.unique(tt_seconds(t_tab, ref_whole), return_index=True)
    return s_tab, np.asarray(r_gcrs_m[keep][order][first], dtype=np.float64), ref_whole


def table_position(s: F64, s_tab: F64, r_tab: F64) -> tuple[F64, NDArray[np.bool_]]:
    """Positions (N, 3) [m] at TT seconds ``s`` from a table of :func:`position_table`:
    exact at its epochs, linear between two at most :data:`MAX_GAP_S` apart, the nearest
    within :data:`NEAR_S` of one elsewhere, NaN (``ok`` False) beyond."""
    out = np.full((s.size, 3), np.nan)
    if s_tab.size < 2:  # no interpolation: the one position near its epoch
        near = np.abs(s - s_tab[0]) <= NEAR_S if s_tab.size else np.zeros(s.size, bool)
        out[near] = r_tab[0] if s_tab.size else np.nan
        return out, near
    inside = (s >= s_tab[0]) & (s <= s_tab[-1])
    k = np.clip(np.searchsorted(s_tab, s, side="right"), 1, s_tab.size - 1)
    between = inside & (s_tab[k] - s_tab[k - 1] <= MAX_GAP_S)
    nearest = np.where(np.abs(s - s_tab[k - 1]) <= np.abs(s - s_tab[k]), k - 1, k)
    near = np.abs(s - s_tab[nearest]) <= NEAR_S
    for axis in range(3):
        out[:, axis] = np.interp(s, s_tab, r_tab[:, axis])
    out[~between] = r_tab[nearest[~between]]
    ok = between | near
    out[~ok] = np.nan
    return out, ok


def observed_trajectory(
    emitted_utc: NDArray[np.datetime64], r_gcrs_m: F64
) -> Callable[[Any], tuple[F64, NDArray[np.bool_]]]:
    """The trajectory through observed positions, for the geometry stage.

    Parameters
    ----------
    emitted_utc
        (M,) UTC epochs at which the light seen left the target (reception time minus the
        one-way light time, or the reception time where light time is off).
    r_gcrs_m
        (M, 3) the target's GCRS positions then [m] (NaN rows: not placed).

    Returns
    -------
    callable
        ``t -> (r (N, 3), ok (N,))``: exact at the given epochs, linear between two given
        epochs at most :data:`MAX_GAP_S` apart (the velocity a nadir attitude needs is the
        chord's), the nearest position within :data:`NEAR_S` of a given epoch elsewhere,
        NaN (``ok`` False) beyond (:func:`table_position`).
    """
    s_tab, r_tab, ref = position_table(emitted_utc, r_gcrs_m)

    def trajectory(t: Any) -> tuple[F64, NDArray[np.bool_]]:
        return table_position(tt_seconds(t, ref), s_tab, r_tab)

    return trajectory
