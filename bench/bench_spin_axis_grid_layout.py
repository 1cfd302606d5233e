"""The spin-axis grid pass: the sums over the epochs by numpy blocks or by the compiled loop
(issue 26 item 4).

Run: ``.venv/bin/python bench/bench_spin_axis_grid_layout.py [--grid-deg 2] [--phases 72]
[--epochs 300] [--reps 3] [--split]``

Two maps in closed form (no render: the cost depends on the layout, not the content), 10
bands, resampled onto the spin frame with ``--phases`` phases: a passive map (HEALPix nside 8
x phase angles 40, 70, 100, 130 deg x 8 rolls: 4 corners per lookup) and a phase-angle-0 map
(nside 32, one geometry: 1 corner per lookup, as ``bench_spin_axis.py``'s); a pass of
``--epochs`` epochs with phase angles 54-117 deg (the box-wing example's); every axis of a
``--grid-deg`` grid. For each map: the bytes of corner windows the pass reads (lookups x
corners x phases x bands x 4 bytes), then the grid pass (:func:`.spin_axis_grid.grid_pass`)
with ``compiled=False`` (numpy blocks: gather, weigh, one pass per sum) and ``compiled=True``
(:mod:`speclight.estimate.spin_axis.spin_axis_window_sums`, numba), interleaved ``--reps``
times in one process, wall and CPU time, and the largest difference of their misfits;
``--split``: where the numpy blocks' time goes (indices, gather, weighing, each sum; CPU
time). Other jobs share the machine: the load average is printed with each run.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from pathlib import Path

import numpy as np

from speclight.estimate.spin_axis.spin_axis_core import radec_grid
from speclight.estimate.spin_axis.spin_axis_corners import epoch_frames, lookup_corners
from speclight.estimate.spin_axis.spin_axis_grid import grid_pass, window_view
from speclight.estimate.spin_axis.spin_axis_lookup import (
    EpochGeometry,
    SpinFrameMap,
    axis_frames,
    spin_frame_map,
)
from speclight.estimate.spin_axis.spin_axis_period import bisector_rates, sidereal_periods
from speclight.estimate.spin_axis.spin_axis_window_sums import compiled_available
from speclight.maps.map_geometry import healpix_directions
from speclight.maps.map_lookup import MapHeader, ReflectivityMap

N_B = 10


def _map(nside: int, angles: list[float], n_rolls: int) -> ReflectivityMap:
    d = healpix_directions(nside)
    a = np.radians(np.asarray(angles))[None, :, None, None]
    r = (2 * np.pi * np.arange(n_rolls) / n_rolls)[None, None, :, None]
    lobes = np.random.default_rng(0).normal(size=(N_B, 3))
    dl = (d @ lobes.T)[:, None, None, :]
    v = 3.0 + dl + 0.6 * dl**2 * np.cos(a) + 0.3 * np.sin(r) * np.sin(a) * d[:, :1, None, None]
    header = MapHeader(
        Path("synthetic"), nside, np.array([500.0]), [f"b{i}" for i in range(N_B)],
        np.asarray(angles, dtype=float), np.arange(n_rolls) * 360.0 / n_rolls, {},
    )  # fmt: skip
    return ReflectivityMap(header, d, v.astype(np.float32))


def _geometry(n_t: int) -> EpochGeometry:
    sun = np.array([1.0, 0.0, 0.0])
    ang = np.radians(np.linspace(54.0, 117.0, n_t))
    tilt = np.radians(20.0)
    obs = np.stack([np.cos(ang), np.sin(ang) * np.cos(tilt), np.sin(ang) * np.sin(tilt)], -1)
    return EpochGeometry(np.tile(sun, (n_t, 1)), obs, np.arange(n_t) * 2.0, 120.0)


def _split(sfm: SpinFrameMap, geo: EpochGeometry, ra: np.ndarray, dec: np.ndarray) -> None:
    """CPU time of the numpy blocks' steps, one axis per block (as grid_pass's default)."""
    ef = epoch_frames(geo, sfm.phase_angle_deg)
    table = window_view(sfm.values)
    n_t = geo.t_s.size
    y = np.ones((n_t, sfm.n_phases * N_B), np.float32)
    cpu = dict.fromkeys(("indices", "gather", "weigh", "sum p", "sum p^2", "sum p y"), 0.0)
    for a0 in range(0, ra.size, 256):
        c0 = time.process_time()
        c = lookup_corners(sfm, ef, axis_frames(ra[a0 : a0 + 256], dec[a0 : a0 + 256]))
        cpu["indices"] += time.process_time() - c0
        for x0 in range(0, c.rows.shape[0], n_t):
            sl = slice(x0, x0 + n_t)
            t = [time.process_time()]
            g = table[c.rows[sl]]
            t.append(time.process_time())
            p = g[:, 0] if c.weights is None else np.matmul(c.weights[sl][:, None, :], g)[:, 0]
            t.append(time.process_time())
            np.add.reduce(p, axis=0)
            t.append(time.process_time())
            np.einsum("tj,tj->j", p, p)
            t.append(time.process_time())
            np.einsum("tj,tj->j", p, y)
            t.append(time.process_time())
            for key, d in zip(list(cpu)[1:], np.diff(t), strict=True):
                cpu[key] += d
    print("  numpy blocks, CPU [s]: " + ", ".join(f"{k} {v:.2f}" for k, v in cpu.items()))


def _compare(label: str, sfm: SpinFrameMap, geo: EpochGeometry, args: argparse.Namespace) -> None:
    ra, dec = radec_grid(args.grid_deg)
    dd, rr = np.meshgrid(dec, ra, indexing="ij")
    ra_all, dec_all = rr.ravel(), dd.ravel()
    n_t = geo.t_s.size
    y = np.abs(np.random.default_rng(1).normal(1.0, 0.2, (n_t, N_B)))
    corners = (2 if sfm.phase_angle_deg.size > 1 else 1) * (2 if sfm.n_rolls > 1 else 1)
    read = ra_all.size * n_t * corners * sfm.n_phases * N_B * 4
    print(
        f"{label}: table {sfm.values.nbytes / 1e6:.1f} MB; {ra_all.size} axes x {n_t} epochs "
        f"x {corners} corners x {sfm.n_phases} phases x {N_B} bands: {read / 1e9:.1f} GB of "
        "corner windows read per pass"
    )
    if args.split:
        _split(sfm, geo, ra_all, dec_all)
    ways = {"numpy blocks": False} | ({"compiled": True} if compiled_available() else {})
    grid_pass(sfm, geo, y, ra_all[:2], dec_all[:2], 256, compiled=compiled_available())  # jit
    times: dict[str, list[float]] = {k: [] for k in ways}
    results = {}
    for _ in range(args.reps):
        for way, compiled in ways.items():
            t0, c0 = time.perf_counter(), time.process_time()
            results[way], _ = grid_pass(sfm, geo, y, ra_all, dec_all, 256, compiled=compiled)
            wall, cpu = time.perf_counter() - t0, time.process_time() - c0
            times[way].append(cpu)
            print(
                f"  {way}: {wall:.2f} s (CPU {cpu:.2f} s, load {os.getloadavg()[0]:.1f})",
                flush=True,
            )
    for way, ts in times.items():
        print(f"  {way}: CPU best {min(ts):.2f} s, median {np.median(ts):.2f} s")
    if len(results) == 2:
        a, b = results["numpy blocks"], results["compiled"]
        ok = np.isfinite(a)
        same = np.array_equal(ok, np.isfinite(b))
        print(
            f"  largest misfit difference {np.max(np.abs(a[ok] - b[ok])):.2e} (same infinite "
            f"cells: {same}); best axis and phase the same: {np.argmin(a) == np.argmin(b)}"
        )
    periods = sidereal_periods(120.0, bisector_rates(geo, ra_all, dec_all))
    t0 = time.perf_counter()
    grid_pass(sfm, geo, y, ra_all, dec_all, 256, period_s_axes=periods)
    print(f"  each axis its own period (synodic): {time.perf_counter() - t0:.2f} s "
          f"(load {os.getloadavg()[0]:.1f})")  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--grid-deg", type=float, default=2.0)
    ap.add_argument("--phases", type=int, default=72)
    ap.add_argument("--epochs", type=int, default=300)
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--split", action="store_true")
    args = ap.parse_args()
    print(f"# {time.strftime('%Y-%m-%d %H:%M')} {platform.node()}, {os.cpu_count()} CPUs")
    geo = _geometry(args.epochs)
    passive = spin_frame_map(_map(8, [40.0, 70.0, 100.0, 130.0], 8), None, args.phases)
    _compare("passive map (nside 8 x 4 x 8)", passive, geo, args)
    phase0 = spin_frame_map(_map(32, [0.0], 1), None, args.phases)
    _compare("phase-0 map (nside 32)", phase0, geo, args)


if __name__ == "__main__":
    main()
