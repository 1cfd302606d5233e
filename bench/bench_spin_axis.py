"""Spin-axis search benchmark (issue 11): 2 deg grid x 72 phases x a 300-epoch pass.

Run: ``.venv/bin/python bench/bench_spin_axis.py [--grid-deg 2] [--phases 72] [--px 16]``

On the built-in box-wing example (100 nm bins, 10 bands, single mode at ``--px``: the map's
content does not change the search's cost, its HEALPix nside and phase angles x rolls do):

1. a phase-angle-0 map of 12,288 directions (nside 32, the issue's 10,000) and a passive map
   of 768 directions x phase angles 40, 70, 100, 130 deg x 8 rolls (nside 8);
2. a 300-epoch pass (2 s steps) simulated from the passive map (``render.mode: map``);
3. for each map: the resampling onto the spin frame, the grid search (RA x Dec cells of
   ``--grid-deg`` x ``--phases``: the misfit of every candidate) and the whole search with
   the Nelder-Mead refinement;
4. a laser pass with ranging returns (the box-wing-laser example, Sun off, its bistatic
   station removed: the laser worked example of docs/spin-axis.md at ``--px`` and 100 nm
   bins), its phase-0 map of 768 directions with range offsets, and ``spin_axis_measured``
   (as ``speclight spin-axis``) without refinement, with the ranging term (default weight)
   and without (``ranging_weight=0``), then with refinement and the ranging term; the
   ``seconds`` it reports (resampling + search);

peak resident memory of the process at the end. Wall and CPU time: other jobs share the
machine.
"""

from __future__ import annotations

import argparse
import os
import platform
import re
import resource
import tempfile
import time
from pathlib import Path

from speclight.estimate.inputs.reflectance_factors import read_reflectance_factors
from speclight.estimate.spin_axis.spin_axis_core import grid_errors, radec_grid, spin_axis_search
from speclight.estimate.spin_axis.spin_axis_lookup import load_band_map, spin_frame_map
from speclight.estimate.spin_axis.spin_axis_run import inertial_epochs, spin_axis_measured
from speclight.io.netcdf import dataset_bytes
from speclight.maps.writer.reflectivity_map_run import reflectivity_map
from speclight.scenario import example_text, load_scenario
from speclight.simulation import simulate
from speclight.simulation.geometry_stage import scenario_geometry


def _text(px: int, render: str | None = None, example: str = "box-wing") -> str:
    text = example_text(example).replace("resolution_px: 256", f"resolution_px: {px}")
    text = text.replace("step_nm: 5", "step_nm: 100").replace("step_s: 1.0", "step_s: 2.0")
    if render is not None:
        text = re.sub(r"render: \{.*\}", render, text)
    return text


def _laser_runs(folder: Path, px: int, grid_deg: float, n_phases: int) -> None:
    """Step 4 of the module docstring."""
    text = _text(px, example="box-wing-laser").replace("sun: true", "sun: false")
    text = re.sub(r"    - \{name: wettzell-532.*\n.*\n.*\n", "", text)  # coaxial lines only
    (folder / "laser.yaml").write_text(text)
    loaded = load_scenario(folder / "laser.yaml")
    reflectivity_map(loaded, folder / "laser.zarr", directions=768, phase_angles_deg=[0], rolls=1)
    (folder / "laser.nc").write_bytes(dataset_bytes(simulate(loaded).dataset))
    for label, weight, refine in (
        ("ranging term, grid only", None, False),
        ("no ranging term (weight 0), grid only", 0.0, False),
        ("ranging term, with refinement", None, True),
    ):
        c0 = time.process_time()
        run = spin_axis_measured(
            loaded,
            folder / "laser.nc",
            folder / "laser.zarr",
            grid_deg=grid_deg,
            n_phases=n_phases,
            refine=refine,
            ranging_weight=weight,
        )
        r = run.result
        print(
            f"laser pass, {r.n_epochs} epochs x {len(r.band_names)} bands, {label}: "
            f"{run.seconds:.2f} s (CPU {time.process_time() - c0:.2f} s, load average "
            f"{os.getloadavg()[0]:.1f}; weight {run.ranging_weight:.3g}); best {r.best[:2]}, "
            f"refined ({r.refined[0]:.1f}, {r.refined[1]:.1f})"
        )


def _solar_runs(folder: Path, args: argparse.Namespace) -> None:
    """Steps 1-3 of the module docstring."""
    (folder / "bw.yaml").write_text(_text(args.px))
    loaded = load_scenario(folder / "bw.yaml")
    t0 = time.perf_counter()
    reflectivity_map(loaded, folder / "active.zarr", directions=10_000, chunk=4096)
    print(f"phase-0 map, 12288 directions: {time.perf_counter() - t0:.1f} s")
    t0 = time.perf_counter()
    reflectivity_map(
        loaded,
        folder / "passive.zarr",
        directions=768,
        phase_angles_deg=[40, 70, 100, 130],
        chunk=768,
    )
    print(f"passive map, 768 directions x 4 x 8: {time.perf_counter() - t0:.1f} s")
    (folder / "pass.yaml").write_text(_text(args.px, "render: {mode: map, map_file: passive.zarr}"))
    ds = simulate(load_scenario(folder / "pass.yaml")).dataset
    (folder / "pass.nc").write_bytes(dataset_bytes(ds))
    rf = read_reflectance_factors(folder / "pass.nc", loaded, light="sun")
    epochs = inertial_epochs(scenario_geometry(loaded, rf.time_utc), 120.0)
    y = rf.factor
    ra, dec = radec_grid(args.grid_deg)
    n_axes = ra.size * dec.size
    print(
        f"pass: {y.shape[0]} epochs x {y.shape[1]} bands; grid {args.grid_deg} deg: "
        f"{ra.size} x {dec.size} = {n_axes} axes x {args.phases} phases"
    )
    for name in ("active", "passive"):
        bmap = load_band_map(folder / f"{name}.zarr")
        t0 = time.perf_counter()
        sfm = spin_frame_map(bmap, None, args.phases)
        t_resample = time.perf_counter() - t0
        t0, c0 = time.perf_counter(), time.process_time()
        grid_errors(sfm, epochs, y, ra, dec)
        t_grid, c_grid = time.perf_counter() - t0, time.process_time() - c0
        t0 = time.perf_counter()
        res = spin_axis_search(bmap, sfm, epochs, y, rf.bands.band_names, args.grid_deg)
        t_all = time.perf_counter() - t0
        print(
            f"{name} map (nside {bmap.header.nside}, {sfm.phase_angle_deg.size} phase "
            f"angles x {sfm.n_rolls} rolls; spin-frame grid {sfm.values.shape[:2]} x "
            f"{sfm.n_phases}): resample {t_resample:.2f} s, grid search {t_grid:.2f} s "
            f"(CPU time of all threads {c_grid:.2f} s; load average {os.getloadavg()[0]:.1f}) "
            f"({t_grid / (n_axes * args.phases * y.shape[0]) * 1e9:.1f} ns per "
            f"candidate-epoch), search with refinement {t_all:.2f} s; best "
            f"{res.best[:2]}, refined ({res.refined[0]:.1f}, {res.refined[1]:.1f})"
        )


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--grid-deg", type=float, default=2.0)
    ap.add_argument("--phases", type=int, default=72)
    ap.add_argument("--px", type=int, default=16)
    ap.add_argument("--cases", default="solar,laser", help="solar, laser or both")
    args = ap.parse_args()
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores")
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        if "solar" in args.cases:
            _solar_runs(folder, args)
        if "laser" in args.cases:
            _laser_runs(folder, args.px, args.grid_deg, args.phases)
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024**2
    print(f"peak resident memory: {rss:.2f} GiB")


if __name__ == "__main__":
    main()
