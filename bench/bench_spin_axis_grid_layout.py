"""The spin-axis grid pass: the corners weighed by ``einsum`` or by ``matmul`` (issue 26 item 4).

Run: ``.venv/bin/python bench/bench_spin_axis_grid_layout.py [--grid-deg 2] [--phases 72]
[--epochs 300] [--reps 3]``

A passive map in closed form (no render: the cost depends on the layout, not the content):
HEALPix nside 8 (768 directions) x phase angles 40, 70, 100, 130 deg x 8 rolls x 10 bands,
resampled onto the spin frame with ``--phases`` phases (4 corners per lookup); a pass of
``--epochs`` epochs with phase angles 54-117 deg (the box-wing example's); every axis of a
``--grid-deg`` grid. The grid pass (:func:`speclight.estimate.spin_axis.spin_axis_grid.grid_pass`)
runs with the module's :func:`gather` (the gathered corners (n, 4, K B) weighed and summed
as ``n`` products ``(1 x 4) @ (4 x K B)`` by ``matmul``) and with the former one (the same by
``einsum("nc,ncj->nj")``), interleaved ``--reps`` times in one process, wall and CPU time;
then the pass with each axis's own period (a synodic period, :mod:`.spin_axis_period`). The
misfits of both are compared (largest difference). Other jobs share the machine: the load
average is printed with each run.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from pathlib import Path

import numpy as np

import speclight.estimate.spin_axis.spin_axis_grid as grid
from speclight.estimate.spin_axis.spin_axis_core import radec_grid
from speclight.estimate.spin_axis.spin_axis_lookup import EpochGeometry, spin_frame_map
from speclight.estimate.spin_axis.spin_axis_period import bisector_rates, sidereal_periods
from speclight.maps.map_geometry import healpix_directions
from speclight.maps.map_lookup import MapHeader, ReflectivityMap


def _map(n_ch: int = 10) -> ReflectivityMap:
    d = healpix_directions(8)
    angles = [40.0, 70.0, 100.0, 130.0]
    a = np.radians(np.asarray(angles))[None, :, None, None]
    r = (2 * np.pi * np.arange(8) / 8)[None, None, :, None]
    lobes = np.random.default_rng(0).normal(size=(n_ch, 3))
    dl = (d @ lobes.T)[:, None, None, :]
    v = 3.0 + dl + 0.6 * dl**2 * np.cos(a) + 0.3 * np.sin(r) * np.sin(a) * d[:, :1, None, None]
    header = MapHeader(
        Path("synthetic"), 8, np.array([500.0]), [f"b{i}" for i in range(n_ch)],
        np.asarray(angles), np.arange(8) * 45.0, {},
    )  # fmt: skip
    return ReflectivityMap(header, d, v.astype(np.float32))


def _geometry(n_t: int) -> EpochGeometry:
    sun = np.array([1.0, 0.0, 0.0])
    ang = np.radians(np.linspace(54.0, 117.0, n_t))
    tilt = np.radians(20.0)
    obs = np.stack([np.cos(ang), np.sin(ang) * np.cos(tilt), np.sin(ang) * np.sin(tilt)], -1)
    return EpochGeometry(np.tile(sun, (n_t, 1)), obs, np.arange(n_t) * 2.0, 120.0)


def _gather_all_corners(table, corners, sl, fill=np.nan):
    """The former :func:`grid.gather`: the gathered corners weighed by ``einsum``."""
    if corners.weights is None:
        out = table[corners.rows[sl, 0]]
    else:
        out = np.einsum("nc,ncj->nj", corners.weights[sl], table[corners.rows[sl]])
    bad = corners.bad[sl]
    if bad.any():
        out[bad] = fill
    return np.asarray(out)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--grid-deg", type=float, default=2.0)
    ap.add_argument("--phases", type=int, default=72)
    ap.add_argument("--epochs", type=int, default=300)
    ap.add_argument("--reps", type=int, default=3)
    args = ap.parse_args()
    print(f"# {time.strftime('%Y-%m-%d %H:%M')} {platform.node()}, {os.cpu_count()} CPUs")
    sfm = spin_frame_map(_map(), None, args.phases)
    geo = _geometry(args.epochs)
    y = np.abs(np.random.default_rng(1).normal(1.0, 0.2, (args.epochs, 10)))
    ra, dec = radec_grid(args.grid_deg)
    dd, rr = np.meshgrid(dec, ra, indexing="ij")
    ra_all, dec_all = rr.ravel(), dd.ravel()
    print(f"{ra_all.size} axes x {args.phases} phases x {args.epochs} epochs x 10 bands")
    new = grid.gather
    times: dict[str, list[float]] = {"matmul (now)": [], "einsum (before)": []}
    results = {}
    for _ in range(args.reps):
        for label, fn in (
            ("einsum (before)", _gather_all_corners),
            ("matmul (now)", new),
        ):
            grid.gather = fn
            t0, c0 = time.perf_counter(), time.process_time()
            e, _ = grid.grid_pass(sfm, geo, y, ra_all, dec_all, 256)
            wall, cpu = time.perf_counter() - t0, time.process_time() - c0
            times[label].append(wall)
            results[label] = e
            print(
                f"{label}: {wall:.2f} s (CPU {cpu:.2f} s, load {os.getloadavg()[0]:.1f})",
                flush=True,
            )
    grid.gather = new
    for label, ts in times.items():
        print(f"{label}: best {min(ts):.2f} s, median {np.median(ts):.2f} s")
    diff = np.max(np.abs(results["matmul (now)"] - results["einsum (before)"]))
    print(f"largest misfit difference: {diff:.2e}")
    periods = sidereal_periods(120.0, bisector_rates(geo, ra_all, dec_all))
    t0 = time.perf_counter()
    grid.grid_pass(sfm, geo, y, ra_all, dec_all, 256, period_s_axes=periods)
    print(f"each axis its own period (synodic): {time.perf_counter() - t0:.2f} s "
          f"(load {os.getloadavg()[0]:.1f})")  # fmt: skip


if __name__ == "__main__":
    main()
