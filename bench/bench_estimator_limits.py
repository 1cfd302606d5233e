"""The rates behind the estimators' up-front time limits (issue 22 item 10; BENCHMARKS.md,
"Estimator limits"): the periodogram per band and frequency and per term, the spin-frame map
per cell and map geometry, the spin-axis grid pass per lookup. Synthetic inputs (no render):
the rates depend on the sizes only.

Run: ``.venv/bin/python bench/bench_estimator_limits.py``
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from speclight.estimate.period.period_run import SECONDS_PER_BAND_FREQUENCY, SECONDS_PER_TERM
from speclight.estimate.period.periodogram import BandSeries, multiband_power
from speclight.estimate.spin_axis.spin_axis_core import grid_terms, radec_grid
from speclight.estimate.spin_axis.spin_axis_limits import (
    SECONDS_PER_CELL_GEOMETRY,
    SECONDS_PER_LOOKUP,
)
from speclight.estimate.spin_axis.spin_axis_lookup import EpochGeometry, spin_frame_map
from speclight.maps.map_geometry import healpix_directions
from speclight.maps.map_lookup import MapHeader, ReflectivityMap


def periodogram() -> None:
    rng = np.random.default_rng(0)
    multiband_power(BandSeries(np.arange(50.0), np.ones(50), np.ones(50), np.zeros(50, np.int64),
                               1), np.linspace(0.01, 0.1, 5), 1)  # fmt: skip  # warm-up
    print("periodogram: points, frequencies, harmonics -> s, model s")
    for n, n_f, k in ((300, 2000, 2), (2000, 400, 2), (300, 400, 6), (20000, 400, 2)):
        t = np.sort(rng.uniform(0, n, n))
        y = np.sin(t / 5) + rng.normal(0, 0.1, n)
        s = BandSeries(np.tile(t, 2), np.tile(y, 2), np.full(2 * n, 0.1), np.repeat([0, 1], n), 2)
        f = np.linspace(0.01, 0.2, n_f)
        t0 = time.perf_counter()
        multiband_power(s, f, k)
        dt = time.perf_counter() - t0
        model = 2 * n_f * (SECONDS_PER_BAND_FREQUENCY + SECONDS_PER_TERM * n * (2 * k + 1) ** 2)
        print(f"  {n:6d} {n_f:5d} {k:2d}: {dt:7.2f} s, model {model:7.2f} s")


def spin_axis() -> None:
    nside, angles, rolls, bands, n_t = 8, 4, 8, 10, 300
    d = healpix_directions(nside)
    rates = np.random.default_rng(1).uniform(1, 2, (d.shape[0], angles, rolls, bands))
    names = [str(b) for b in range(bands)]
    angle_deg, roll_deg = np.linspace(40, 130, angles), np.arange(rolls) * 360.0 / rolls
    header = MapHeader(Path("synthetic"), nside, np.array([500.0]), names, angle_deg, roll_deg, {})
    bmap = ReflectivityMap(header, d, rates.astype(np.float32))
    print("spin axis: phases, grid -> spin-frame map s (per cell x geometry), grid s")
    ang = np.radians(np.linspace(0, 60, n_t))
    sun = np.stack([np.cos(ang), np.sin(ang), np.zeros(n_t)], -1)
    obs = np.stack([np.cos(ang + 1), np.sin(ang + 1), np.zeros(n_t)], -1)
    geo = EpochGeometry(sun, obs, np.linspace(0, 600, n_t), 120.0)
    y = np.random.default_rng(2).uniform(1, 2, (n_t, bands))
    for n_phases, grid in ((36, 10.0), (72, 5.0), (360, 10.0)):
        t0 = time.perf_counter()
        sfm = spin_frame_map(bmap, None, n_phases)
        t_map = time.perf_counter() - t0
        cells = sfm.values.shape[0] * sfm.values.shape[1] * n_phases * angles * rolls
        ra, dec = radec_grid(grid)
        t0 = time.perf_counter()
        grid_terms(sfm, geo, y, ra, dec)
        t_grid = time.perf_counter() - t0
        lookups = ra.size * dec.size * n_phases * n_t * bands
        print(
            f"  {n_phases:4d} {grid:4g}: map {t_map:6.2f} s ({t_map / cells * 1e6:5.1f} us, "
            f"limit {SECONDS_PER_CELL_GEOMETRY * 1e6:g}), grid {t_grid:6.2f} s "
            f"({t_grid / lookups * 1e9:5.1f} ns, limit {SECONDS_PER_LOOKUP * 1e9:g})"
        )


if __name__ == "__main__":
    periodogram()
    spin_axis()
