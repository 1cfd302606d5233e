"""Reflectivity-map benchmark (issue 11): map cost against the simulate pipeline's per epoch.

Run: ``.venv/bin/python bench/bench_reflectivity_map.py [--directions 10000] [--px 128]
[--passive-chunks 1] [--error-samples 300] [--scheduler none,local] [--workers 2]
[--map-only]``

All on the built-in box-wing example (189 bins, 300-1240 nm), single mode at ``--px``, in one
process unless ``--scheduler`` says otherwise:

1. the simulate pipeline on the example's 600-epoch pass at the same resolution (once to
   warm up on 10 epochs, then timed): seconds per epoch;
2. the phase-angle-0 map of ``--directions`` (HEALPix: the next 12 nside^2), once per
   ``--scheduler`` (``none``: in this process; ``local``: a local Dask cluster of
   ``--workers`` workers, its start timed apart; or a scheduler address): seconds, seconds
   per direction, the ratio to 1., and on a cluster each worker's peak resident memory;
3. the passive map (phase angles 0, 30, 60, 90 x 8 rolls) estimated from its first
   ``--passive-chunks`` chunks of 512 directions (the rest extrapolated per chunk);
4. ``render.mode: map``: the 600-epoch pass with the phase-0 map, the interpolation alone
   (map loaded) and the whole simulate run;
4b. ``render.mode: map`` with lasers: the ``box-wing-laser`` example's 600-epoch pass (seven
   coaxial lines and the bistatic Wettzell station) from a map of ``--laser-directions``
   directions at phase angles 0, 15, 30 deg x 8 rolls, ``--laser-px`` px, 20 nm bins (the
   lookup's cost does not depend on the resolution, and little on the directions): the
   lasers' returns from the map alone (map loaded), the whole simulate run with the geometry
   given, and the error against the same pass rendered (return photons per pulse per laser
   and band, range offsets per band); ``--laser-only`` runs this step alone;
5. the interpolation error of the phase-0 map against direct renders (``--error-samples``
   random directions, intensity summed over wavelength, ``|map / render - 1|``);
6. peak resident memory (``ru_maxrss``) of the process.

``--worker-memory`` instead renders one passive chunk (512 directions x 25 geometries) on a
local cluster of one worker and prints that worker's peak resident memory.
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

from speclight.illumination import solar_irradiance_W_m2_nm
from speclight.maps.map_geometry import sun_observer
from speclight.maps.map_lookup import load_map
from speclight.maps.writer.reflectivity_map_run import reflectivity_map
from speclight.render import render_intensity
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate
from speclight.simulation.radiometry import wavelength_grid_nm
from speclight.simulation.ranging_stage import prepare_ranging
from speclight.simulation.reflection import build_target


def _scenario(
    px: int,
    render: str | None = None,
    folder: Path | None = None,
    example: str = "box-wing",
    step_nm: int | None = None,
):  # type: ignore[no-untyped-def]
    text = re.sub(r"resolution_px: \d+", f"resolution_px: {px}", example_text(example))
    if step_nm is not None:
        text = re.sub(r"step_nm: \d+", f"step_nm: {step_nm}", text)
    if render is not None:
        text = re.sub(r"render: \{.*\}", render, text)
    return parse_scenario(text, source="box-wing (bench)", base_dir=folder)


def _rss_gib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20


def _phase0_map(  # type: ignore[no-untyped-def]
    loaded, folder: Path, directions: int, scheduler: str, workers: int | None, per_epoch: float
) -> None:
    """Step 2 on one scheduler; on a cluster, its start apart and the workers' peak RSS."""
    from speclight.scale import open_executor

    t0 = time.perf_counter()
    with open_executor(scheduler, n_workers=workers) as ex:
        start_s = time.perf_counter() - t0
        address = "none" if ex.serial else ex.client.scheduler.address
        t0 = time.perf_counter()
        run = reflectivity_map(
            loaded, folder / "map0.zarr", directions=directions, force=True, scheduler=address
        )
        seconds = time.perf_counter() - t0
        rss = {} if ex.serial else ex.client.run(_rss_gib)
    per_dir = seconds / run.n_directions
    where = "in process" if ex.serial else f"{ex.description}, started in {start_s:.1f} s"
    print(
        f"phase-0 map ({where}): {run.n_directions} directions in {seconds:.1f} s "
        f"({(seconds + start_s) / run.n_directions * 1e4:.1f} s per 10,000 with the start), "
        f"{per_dir * 1e3:.2f} ms per direction ({per_dir / per_epoch:.2f} x simulate's per "
        f"epoch), peak RSS of this process so far {_rss_gib():.2f} GiB"
    )
    if rss:
        print("  peak RSS per worker: " + ", ".join(f"{v:.2f} GiB" for v in rss.values()))


def _worker_memory(loaded, folder: Path, directions: int) -> None:  # type: ignore[no-untyped-def]
    """Peak RSS of a worker for one passive chunk (512 directions x 25 geometries)."""
    from speclight.scale import open_executor

    with open_executor("local", n_workers=1) as ex:
        start = ex.client.run(_rss_gib)
        t0 = time.perf_counter()
        reflectivity_map(
            loaded,
            folder / "passive-worker.zarr",
            directions=directions,
            phase_angles_deg=[0, 30, 60, 90],
            rolls=8,
            max_chunks=1,
            scheduler=ex.client.scheduler.address,
        )
        seconds = time.perf_counter() - t0
        peak = ex.client.run(_rss_gib)
    print(
        f"one passive chunk on a 1-worker local cluster: {seconds:.1f} s; worker peak RSS "
        f"{max(peak.values()):.2f} GiB ({max(start.values()):.2f} GiB after its start); this "
        f"process (no render) {_rss_gib():.2f} GiB"
    )


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--directions", type=int, default=10_000)
    ap.add_argument("--px", type=int, default=128)
    ap.add_argument("--passive-chunks", type=int, default=1)
    ap.add_argument("--error-samples", type=int, default=300)
    ap.add_argument("--laser-directions", type=int, default=3072)
    ap.add_argument("--laser-px", type=int, default=32)
    ap.add_argument("--laser-only", action="store_true")
    ap.add_argument("--scheduler", default="none", help="comma-separated: none, local, ADDRESS")
    ap.add_argument("--workers", type=int, default=None, help="workers of a local cluster")
    ap.add_argument("--map-only", action="store_true", help="steps 1-2 only")
    ap.add_argument(
        "--worker-memory",
        action="store_true",
        help="only: one passive chunk on a 1-worker local cluster, the worker's peak RSS",
    )
    args = ap.parse_args()
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, {args.px} px")
    folder = Path(tempfile.mkdtemp(prefix="bench-refmap-"))
    if args.laser_only:
        laser_pass(args, folder)
        print(f"peak RSS {_rss_gib():.2f} GiB")
        return
    loaded = _scenario(args.px, folder=folder)
    if args.worker_memory:
        _worker_memory(loaded, folder, args.directions)
        return

    t_s = np.datetime64("2019-08-30T02:20:00") + np.arange(10) * np.timedelta64(1, "s")
    simulate(loaded, time_utc=t_s)  # warm-up: kernels, tables
    t0 = time.perf_counter()
    n_epochs = simulate(loaded).dataset.sizes["time"]
    per_epoch = (time.perf_counter() - t0) / n_epochs
    print(f"simulate: {n_epochs} epochs, {per_epoch * 1e3:.2f} ms per epoch")

    for scheduler in args.scheduler.split(","):
        _phase0_map(loaded, folder, args.directions, scheduler.strip(), args.workers, per_epoch)
    if args.map_only:
        print(f"peak RSS {_rss_gib():.2f} GiB")
        return

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
    laser_pass(args, folder)
    print(f"peak RSS {_rss_gib():.2f} GiB")


def laser_pass(args: argparse.Namespace, folder: Path) -> None:
    """Step 4b of the module docstring."""
    px, step = args.laser_px, 20
    loaded = _scenario(px, None, folder, "box-wing-laser", step)
    t0 = time.perf_counter()
    run = reflectivity_map(
        loaded,
        folder / "laser.zarr",
        directions=args.laser_directions,
        phase_angles_deg=[0, 15, 30],
        rolls=8,
        force=True,
    )
    print(
        f"laser map ({px} px, phase 0/15/30 x 8 rolls): {run.n_directions} directions in "
        f"{time.perf_counter() - t0:.1f} s"
    )
    rendered = simulate(loaded).dataset
    map_loaded = _scenario(
        px, "render: {mode: map, map_file: laser.zarr}", folder, "box-wing-laser", step
    )
    with warnings.catch_warnings():  # the Sun's phase angles beyond 30 deg: known
        warnings.simplefilter("ignore")
        result = simulate(map_loaded)  # warm-up (and the geometry, reused below)
        geo = result.geometry
        wl = wavelength_grid_nm(map_loaded.scenario.spectrum)
        setup = prepare_ranging(map_loaded, geo, wl, None, None)
        assert setup is not None and setup.map_returns is not None
        t0 = time.perf_counter()
        setup.map_returns()
        lookup_s = time.perf_counter() - t0
        t0 = time.perf_counter()
        simulate(map_loaded, geometry=geo)
        whole_s = time.perf_counter() - t0
    n_las = len(map_loaded.scenario.illumination.lasers)
    print(
        f"render.mode map with {n_las} lasers, {geo.t_s.size} epochs: laser returns from the "
        f"map {lookup_s * 1e3:.1f} ms, simulate with the geometry given {whole_s:.2f} s"
    )
    a, b = result.dataset, rendered
    x, y = a["return_photons_per_pulse"].values, b["return_photons_per_pulse"].values
    with np.errstate(invalid="ignore", divide="ignore"):
        err = np.abs(x / y - 1)
    names = list(a["laser"].values)
    for kind in ("coaxial", "bistatic"):
        k = [i for i, n in enumerate(names) if n.startswith("wettzell") == (kind == "bistatic")]
        e = err[:, k][np.isfinite(err[:, k]) & (y[:, k] > 0)]
        print(
            f"laser error ({kind}), return photons per pulse: median {np.median(e):.4f}, "
            f"95th percentile {np.percentile(e, 95):.4f}"
        )
    d = np.abs(a["range_offset"].values - b["range_offset"].values)
    d = d[np.isfinite(d)]
    print(
        f"range offset error: median {np.median(d) * 1e3:.1f} mm, 95th percentile "
        f"{np.percentile(d, 95) * 1e3:.1f} mm"
    )


if __name__ == "__main__":
    main()
