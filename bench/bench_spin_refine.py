"""Spin-axis refinement from far starts (issue 15): which method converges, at what cost.

Run: ``.venv/bin/python bench/bench_spin_refine.py [--px 32] [--bearings 6] [--case rendered]``

The worked example of docs/spin-axis.md: the box-wing example at ``--px``, 20 nm bins, 300
epochs at 2 s (RA 30, Dec 45, phase 0, period 120 s), a passive map of 768 directions x
phase angles 40, 70, 100, 130 deg x 8 rolls. ``--case rendered``: the pass rendered (with
the example's noise, so the map is only an approximation of it); ``--case map``: the pass
simulated from the map itself (``render.mode: map``, with noise): the misfit's minimum is
then at the truth up to the noise.

1. The **optimum**: every method refined from the truth; the lowest misfit (with the period
   fixed, and again with it free within 5 %).
2. **Starts**: the axis 5, 10, 20, 40, 60, 90 deg from the optimum (``--bearings`` seeded
   random directions each) with the phase within +-15 deg of the optimum's; the axis at
   the optimum with the phase 10, 20, 45, 90, 135 deg off (both signs); the period free
   (bound 5 %) and started 0.5 % and 2 % off (both signs), axis 10 deg off, phase +-10 deg.
3. Each method (Nelder-Mead, gradient = L-BFGS-B with the analytic gradient,
   gradient-continuation = the same on coarsened maps first, Gauss-Newton = least squares
   with the analytic Jacobian, SLSQP with numerical gradients) from each start;
   **converged**: the axis within 1 deg and the phase within 1 deg of the optimum or of its
   **twin** (the same axis, the phase + 180 deg: the box-wing turned half a turn
   about its antenna is the same shape, and the twin's misfit is the optimum's), and the
   period within 0.05 %; ``(k twin)`` counts the starts that ended at the twin. Printed:
   converged / tried, the median misfit and gradient evaluations and the median wall time
   per start, and for the starts that did not converge the median of their final misfit
   over the optimum's (``e/e*``).
4. The cost of one misfit and of one misfit with its gradient (30 each, interleaved).
5. The whole search (``spin_axis_search``: 2 deg grid x 72 phases), then each method's
   refinement from its best and mirror cells (as the search does): the refined axis, its
   distance from the optimum, the evaluations and the seconds of the refinement.

Other jobs share the machine: the seconds are indicative, the evaluation counts are not
disturbed.
"""

from __future__ import annotations

import argparse
import os
import platform
import re
import tempfile
import time
from pathlib import Path

import numpy as np

from speclight.estimate.inputs.reflectance_factors import read_reflectance_factors
from speclight.estimate.spin_axis.spin_axis_core import angular_distance_deg, spin_axis_search
from speclight.estimate.spin_axis.spin_axis_gradient import SpinMisfit
from speclight.estimate.spin_axis.spin_axis_lookup import load_band_map, spin_frame_map
from speclight.estimate.spin_axis.spin_axis_refine import REFINE_METHODS, refine_candidate
from speclight.estimate.spin_axis.spin_axis_run import inertial_epochs
from speclight.io.netcdf import dataset_bytes
from speclight.maps.writer.reflectivity_map_run import reflectivity_map
from speclight.scenario import example_text, load_scenario
from speclight.simulation import simulate
from speclight.simulation.geometry_stage import scenario_geometry

TRUTH = (30.0, 45.0, 0.0)
BOUND = 0.05


def _text(px: int, render: str | None = None) -> str:
    text = example_text("box-wing").replace("resolution_px: 256", f"resolution_px: {px}")
    text = text.replace("step_nm: 5", "step_nm: 20").replace("step_s: 1.0", "step_s: 2.0")
    if render is not None:
        text = re.sub(r"render: \{.*\}", render, text)
    return text


def _problem(folder: Path, px: int, case: str):
    (folder / "bw.yaml").write_text(_text(px))
    loaded = load_scenario(folder / "bw.yaml")
    t0 = time.perf_counter()
    reflectivity_map(
        loaded, folder / "map.zarr", directions=768, phase_angles_deg=[40, 70, 100, 130], rolls=8
    )
    print(f"map: {time.perf_counter() - t0:.1f} s")
    if case == "map":
        render = f"render: {{mode: map, map_file: {folder / 'map.zarr'}}}"
        (folder / "pass.yaml").write_text(_text(px, render))
        sim = load_scenario(folder / "pass.yaml")
    else:
        sim = loaded
    (folder / "pass.nc").write_bytes(dataset_bytes(simulate(sim).dataset))
    rf = read_reflectance_factors(folder / "pass.nc", loaded)
    geo = scenario_geometry(loaded, rf.time_utc)
    epochs = inertial_epochs(geo, 120.0)
    y = np.where((geo.observable & (geo.sunlit_fraction > 0))[:, None], rf.factor, np.nan)
    ok = np.all(np.isfinite(y), axis=1)
    epochs = type(epochs)(
        epochs.sun_gcrs[ok], epochs.observer_gcrs[ok], epochs.t_s[ok], epochs.period_s
    )
    return load_band_map(folder / "map.zarr"), epochs, y[ok]


def _offset_axis(ra: float, dec: float, dist: float, bearing: float) -> tuple[float, float]:
    r, d = np.radians(ra), np.radians(dec)
    z = np.array([np.cos(d) * np.cos(r), np.cos(d) * np.sin(r), np.sin(d)])
    e = np.cross([0.0, 0.0, 1.0], z)
    e /= np.linalg.norm(e)
    n = np.cross(z, e)
    a = np.radians(dist)
    v = np.cos(a) * z + np.sin(a) * (np.cos(bearing) * e + np.sin(bearing) * n)
    return float(np.degrees(np.arctan2(v[1], v[0])) % 360), float(np.degrees(np.arcsin(v[2])))


def _dphase(a: float, b: float) -> float:
    return abs((a - b + 180.0) % 360.0 - 180.0)


def start_sets(
    optimum: dict, rng: np.random.Generator, bearings: int, period: bool = True
) -> list[tuple[str, list, float | None]]:
    """The starts, drawn in this order: axis offsets (5-90 deg, ``bearings`` random bearings
    each), phase offsets, and (``period``) the period 0.5 % / 2 % off with the axis 10 deg
    off. ``optimum[None]`` / ``optimum[BOUND]``: the optimum with the period fixed / free."""
    sets: list[tuple[str, list, float | None]] = []
    o = optimum[None]
    for dist in (5, 10, 20, 40, 60, 90):
        starts = []
        for _ in range(bearings):
            ra, dec = _offset_axis(o.ra_deg, o.dec_deg, dist, rng.uniform(0, 2 * np.pi))
            starts.append(((ra, dec, o.phase_deg + rng.uniform(-15, 15)), None))
        sets.append((f"axis {dist} deg off", starts, None))
    for dph in (10, 20, 45, 90, 135):
        starts = [((o.ra_deg, o.dec_deg, o.phase_deg + s * dph), None) for s in (-1, 1)]
        sets.append((f"phase {dph} deg off", starts, None))
    of = optimum[BOUND]
    for rel in (0.005, 0.02):
        starts = []
        for sign in (-1, 1):
            for _ in range(max(1, bearings // 2)):
                ra, dec = _offset_axis(of.ra_deg, of.dec_deg, 10, rng.uniform(0, 2 * np.pi))
                ph = of.phase_deg + rng.uniform(-10, 10)
                starts.append(((ra, dec, ph), 120.0 * (1 + sign * rel)))
        if period:
            sets.append((f"period {rel * 100:g} % off (free), axis 10 deg off", starts, BOUND))
    return sets


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--px", type=int, default=32)
    ap.add_argument("--bearings", type=int, default=10)
    ap.add_argument("--case", choices=("rendered", "map"), default="rendered")
    args = ap.parse_args()
    print(f"{platform.node()} {platform.processor() or platform.machine()}, {os.cpu_count()} CPUs")
    rng = np.random.default_rng(15)
    with tempfile.TemporaryDirectory() as tmp:
        bmap, geo, y = _problem(Path(tmp), args.px, args.case)
    print(f"case {args.case}: {y.shape[0]} epochs x {y.shape[1]} bands")
    step = 2.5  # the spin-axis default: max(grid 2 deg, 360 / 72 phases) / 2

    def run(method: str, start, bound=None, p_start=None):
        t0 = time.perf_counter()
        r = refine_candidate(bmap, geo, y, None, start, step, method, bound, None, p_start)
        return r, time.perf_counter() - t0

    optimum = {}
    for bound in (None, BOUND):
        res = [run(m, TRUTH, bound)[0] for m in REFINE_METHODS]
        best = min(res, key=lambda r: r.error)
        optimum[bound] = best
        print(
            f"optimum (period {'free' if bound else 'fixed'}): RA {best.ra_deg:.3f} Dec "
            f"{best.dec_deg:.3f} phase {best.phase_deg:.3f} period {best.period_s:.4f} s, "
            f"misfit {best.error:.6g}; from the truth: "
            + ", ".join(
                f"{m} {angular_distance_deg(r.ra_deg, r.dec_deg, best.ra_deg, best.dec_deg):.2f}"
                f" deg {r.error:.6g}"
                for m, r in zip(REFINE_METHODS, res, strict=True)
            )
        )
    sets = start_sets(optimum, rng, args.bearings)
    print("\n| starts | " + " | ".join(REFINE_METHODS) + " |")
    print("|---|" + "---|" * len(REFINE_METHODS))
    for label, starts, bound in sets:
        ref = optimum[bound]
        cells = []
        for m in REFINE_METHODS:
            ok, twin, nf, ng, sec, ratio = 0, 0, [], [], [], []
            for start, p0 in starts:
                r, s = run(m, start, bound, p0)
                good = angular_distance_deg(r.ra_deg, r.dec_deg, ref.ra_deg, ref.dec_deg) < 1.0
                good &= abs(r.period_s / ref.period_s - 1) < 5e-4
                is_twin = good and _dphase(r.phase_deg, ref.phase_deg + 180.0) < 1.0
                good &= _dphase(r.phase_deg, ref.phase_deg) < 1.0 or is_twin
                ok += int(good)
                twin += int(is_twin)
                nf.append(r.n_misfit)
                ng.append(r.n_gradient)
                sec.append(s)
                if not good:
                    ratio.append(r.error / ref.error)
            fail = f"; e/e* {np.median(ratio):.4g}" if ratio else ""
            tw = f" ({twin} twin)" if twin else ""
            cells.append(
                f"{ok}/{len(starts)}{tw}: {np.median(nf):.0f} + {np.median(ng):.0f}g, "
                f"{np.median(sec):.2f} s{fail}"
            )
        print(f"| {label} | " + " | ".join(cells) + " |", flush=True)
    _costs(bmap, geo, y)
    _whole_search(bmap, geo, y, optimum[None])


def _costs(bmap, geo, y) -> None:
    """Step 4 of the module docstring."""
    model = SpinMisfit.around(bmap, geo, y, None, *TRUTH[:2])
    x = np.array([0.01, -0.02, 0.1])
    model.misfit_and_gradient(x)  # warm up
    times: dict[str, list[float]] = {"misfit": [], "misfit + gradient": []}
    for _ in range(30):  # interleaved, so that both see the same load
        for label, f in (
            ("misfit", model.misfit),
            ("misfit + gradient", model.misfit_and_gradient),
        ):
            t0 = time.perf_counter()
            f(x)
            times[label].append(time.perf_counter() - t0)
    for label, t in times.items():
        print(f"one {label}: min {np.min(t) * 1e3:.2f} ms, median {np.median(t) * 1e3:.2f} ms")


def _whole_search(bmap, geo, y, o) -> None:
    """Step 5 of the module docstring."""
    sfm = spin_frame_map(bmap, None, 72)
    t0 = time.perf_counter()
    grid = spin_axis_search(bmap, sfm, geo, y, [], 2.0, do_refine=False)
    print(f"grid search 2 deg x 72 phases: {time.perf_counter() - t0:.1f} s")
    starts = [grid.best[:3]] + ([grid.mirror[:3]] if np.isfinite(grid.mirror[0]) else [])
    step = max(2.0, 360.0 / 72) / 2
    for m in REFINE_METHODS:
        t0 = time.perf_counter()
        tries = [refine_candidate(bmap, geo, y, None, st, step, m) for st in starts]
        sec = time.perf_counter() - t0
        r = min(tries, key=lambda t: t.error)
        d = angular_distance_deg(r.ra_deg, r.dec_deg, o.ra_deg, o.dec_deg)
        print(
            f"{m}: refined RA {r.ra_deg:.3f} Dec {r.dec_deg:.3f} phase {r.phase_deg:.2f} misfit "
            f"{r.error:.6g} ({d:.2f} deg from the optimum), "
            f"{sum(t.n_misfit for t in tries)} misfit + {sum(t.n_gradient for t in tries)} "
            f"gradient evaluations, refinement {sec:.2f} s (best and mirror cells)"
        )


if __name__ == "__main__":
    main()
