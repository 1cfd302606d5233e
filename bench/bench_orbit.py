"""Benchmark of the orbit stage: one day at 1 s steps (86,400 epochs).

Times TLE propagation (SGP4 + TEME->GCRS), the Sun, the Earth shadow and topocentric
range/azimuth/elevation for LCS 1 seen from Stuttgart, as ``observation_geometry`` runs them.

Run: ``.venv/bin/python bench/bench_orbit.py``
"""

from __future__ import annotations

import time

import numpy as np

from speclight.orbit import (
    Site,
    as_time,
    earth_orientation,
    observation_geometry,
    parse_tle,
    sun_position_gcrs_m,
    sunlit_fraction,
    tle_position_gcrs_m,
    topocentric,
)

TLE = """LCS 1
1 01361U 65034C   20199.53569372  .00000028  00000-0  25492-2 0  9994
2 01361  32.1395 267.1291 0005455 248.0922 111.8996  9.89297492995906"""
SITE = Site(48.7822, 9.1967, 355.0)
N_EPOCHS = 86_400


def run_once() -> dict[str, float]:
    """Time each step once; returns seconds per step and the total."""
    tle = parse_tle(TLE)
    times = np.datetime64("2020-11-27T00:00:00", "ns") + np.arange(N_EPOCHS) * np.timedelta64(
        1, "s"
    )
    out: dict[str, float] = {}
    t0 = time.perf_counter()
    t = as_time(times)
    out["time conversion"] = time.perf_counter() - t0
    t1 = time.perf_counter()
    eo = earth_orientation(t)
    out["earth orientation (fast path)"] = time.perf_counter() - t1
    t1 = time.perf_counter()
    r, _ = tle_position_gcrs_m(tle, t, orientation=eo)
    out["SGP4 + TEME->GCRS"] = time.perf_counter() - t1
    t1 = time.perf_counter()
    r_sun = sun_position_gcrs_m(t)
    out["Sun (DE421)"] = time.perf_counter() - t1
    t1 = time.perf_counter()
    sunlit_fraction(r, r_sun)
    out["shadow"] = time.perf_counter() - t1
    t1 = time.perf_counter()
    topocentric(SITE, r, t, orientation=eo)
    out["topocentric"] = time.perf_counter() - t1
    out["sum of steps"] = time.perf_counter() - t0
    t1 = time.perf_counter()
    t = as_time(times)
    eo = earth_orientation(t)
    r, _ = tle_position_gcrs_m(tle, t, orientation=eo)
    observation_geometry(t, r, SITE, orientation=eo)
    out["end to end: TLE + observation_geometry"] = time.perf_counter() - t1
    return out


def main() -> None:
    cold = run_once()  # includes loading the ephemeris and the IERS table
    warm = [run_once() for _ in range(3)]
    print(f"orbit stage, {N_EPOCHS} epochs (1 day at 1 s), LCS 1 from Stuttgart")
    print(f"{'step':40s} {'cold [s]':>9s} {'warm best [s]':>14s}")
    for key in cold:
        best = min(w[key] for w in warm)
        print(f"{key:40s} {cold[key]:9.3f} {best:14.3f}")


if __name__ == "__main__":
    main()
