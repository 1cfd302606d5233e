"""Reflectivity-map benchmark (issue 11): map cost against the simulate pipeline's per epoch.

Run: ``.venv/bin/python bench/bench_reflectivity_map.py [--directions 10000] [--px 128]
[--passive-chunks 1] [--error-samples 300]``

All on the built-in box-wing example (189 bins, 300-1240 nm), single mode at ``--px``, in one
process:

1. the simulate pipeline on the example's 600-epoch pass at the same resolution (once to
   warm up on 10 epochs, then timed): seconds per epoch;
2. the phase-angle-0 map of ``--directions`` (HEALPix: the next 12 nside^2) in one run:
   total seconds, seconds per direction, the ratio to 1.;
3. the passive map (phase angles 0, 30, 60, 90 x 8 rolls) estimated from its first
   ``--passive-chunks`` chunks of 512 directions (the rest extrapolated per chunk);
4. ``render.mode: map``: the 600-epoch pass with the phase-0 map, the interpolation alone
   (map loaded) and the whole simulate run;
5. the interpolation error of the phase-0 map against direct renders (``--error-samples``
   random directions, intensity summed over wavelength, ``|map / render - 1|``);
6. peak resident memory (``ru_maxrss``) of the process.
"""

from __future__ import annotations

import argparse
import os
import platform
import re
import resource
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

from speclight.estimate.reflectivity_map import reflectivity_map
from speclight.illumination import solar_irradiance_W_m2_nm
from speclight.render import render_intensity
from speclight.render.map_geometry import sun_observer
from speclight.render.map_lookup import load_map
from speclight.scenario import example_text, parse_scenario
from speclight.simulate import simulate
from speclight.simulate.radiometry import wavelength_grid_nm
from speclight.simulate.reflection import build_target


def _scenario(px: int, render: str | None = None, folder: Path | None = None):  # type: ignore[no-untyped-def]
    text = re.sub(r"resolution_px: \d+", f"resolution_px: {px}", example_text("box-wing"))
    if render is not None:
        text = re.sub(r"render: \{.*\}", render, text)
    return parse_scenario(text, source="box-wing (bench)", base_dir=folder)


def _rss_gib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--directions", type=int, default=10_000)
    ap.add_argument("--px", type=int, default=128)
    ap.add_argument("--passive-chunks", type=int, default=1)
    ap.add_argument("--error-samples", type=int, default=300)
    args = ap.parse_args()
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, {args.px} px")
    folder = Path(tempfile.mkdtemp(prefix="bench-refmap-"))
    loaded = _scenario(args.px, folder=folder)

    t_s = np.datetime64("2019-08-30T02:20:00") + np.arange(10) * np.timedelta64(1, "s")
    simulate(loaded, time_utc=t_s)  # warm-up: kernels, tables
    t0 = time.perf_counter()
    n_epochs = simulate(loaded).dataset.sizes["time"]
    per_epoch = (time.perf_counter() - t0) / n_epochs
    print(f"simulate: {n_epochs} epochs, {per_epoch * 1e3:.2f} ms per epoch")

    t0 = time.perf_counter()
    run = reflectivity_map(loaded, folder / "map0.zarr", directions=args.directions, force=True)
    seconds = time.perf_counter() - t0
    per_dir = seconds / run.n_directions
    print(
        f"phase-0 map: {run.n_directions} directions in {seconds:.1f} s, "
        f"{per_dir * 1e3:.2f} ms per direction ({per_dir / per_epoch:.2f} x simulate's per epoch)"
        f", peak RSS so far {_rss_gib():.2f} GiB"
    )

    k = args.passive_chunks
    t0 = time.perf_counter()
    part = reflectivity_map(
        loaded,
        folder / "passive.zarr",
        directions=args.directions,
        phase_angles_deg=[0, 30, 60, 90],
        rolls=8,
        max_chunks=k,
        force=True,
    )
    seconds = time.perf_counter() - t0
    estimate = seconds / k * part.n_chunks
    print(
        f"passive map (4 phase angles x 8 rolls): {k} of {part.n_chunks} chunks in "
        f"{seconds:.1f} s, whole map about {estimate / 60:.1f} min"
    )

    the_map = load_map(folder / "map0.zarr")
    map_loaded = _scenario(args.px, "render: {mode: map, map_file: map0.zarr}", folder)
    with warnings.catch_warnings():  # the pass lies outside the phase-0 map's angles: known
        warnings.simplefilter("ignore")
        result = simulate(map_loaded)  # warm-up (and the geometry, reused below)
    geo = result.geometry
    t0 = time.perf_counter()
    the_map.intensity_1au(geo.sun_direction_body, geo.observer_direction_body)
    lookup_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        simulate(map_loaded, geometry=geo)
    whole_s = time.perf_counter() - t0
    print(
        f"render.mode map, {geo.t_s.size} epochs: interpolation {lookup_s * 1e3:.1f} ms, "
        f"simulate with the geometry given {whole_s:.2f} s"
    )

    n = args.error_samples
    rng = np.random.default_rng(1)
    p = rng.normal(size=(n, 3))
    p /= np.linalg.norm(p, axis=1)[:, None]
    s, o = sun_observer(p, 0.0, 0.0)
    wl = wavelength_grid_nm(loaded.scenario.spectrum)
    direct = render_intensity(
        build_target(loaded), s, o, solar_irradiance_W_m2_nm(wl, 1.0), wl, resolution_px=args.px
    ).intensity_W_sr_nm.sum(axis=1)
    err = np.abs(the_map.intensity_1au(s, o).sum(axis=1) / direct - 1)
    print(
        f"interpolation error, phase 0, nside {the_map.header.nside}: median "
        f"{np.median(err):.4f}, 95th percentile {np.percentile(err, 95):.4f}"
    )
    print(f"peak RSS {_rss_gib():.2f} GiB")


if __name__ == "__main__":
    main()
