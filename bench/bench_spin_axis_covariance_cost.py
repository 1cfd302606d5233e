"""CPU of one spin-axis run and of its covariance by method, on the calibration's draws.

Run: ``.venv/bin/python bench/bench_spin_axis_covariance_cost.py [--draws 4] [--seed 2]
[--folder DIR]`` (the maps of ``bench_calibration_spin_axis.py`` in ``DIR``): per draw the
search (grid 4 deg x 36 phases, Nelder-Mead, the period check, the default covariance),
then :func:`speclight.estimate.spin_axis.spin_axis_confidence.axis_confidence` again with
each method; CPU seconds per draw.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import time
from pathlib import Path

import numpy as np

from bench_calibration_spin_axis import pass_geometry, truth_draw
from speclight.estimate.spin_axis.spin_axis_confidence import axis_confidence
from speclight.estimate.spin_axis.spin_axis_core import spin_axis_search
from speclight.estimate.spin_axis.spin_axis_lookup import load_band_map, spin_frame_map

METHODS = ("jackknife-shrunk", "sandwich-warp", "jackknife-warp")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--draws", type=int, default=4)
    ap.add_argument("--seed", type=int, default=2)
    ap.add_argument("--folder", type=Path, default=Path("/tmp/bench_calibration_spin_axis"))
    args = ap.parse_args()
    geo_all = pass_geometry(args.folder)
    truth = load_band_map(args.folder / "bw-32-3072.zarr")
    bmap = load_band_map(args.folder / "bw-32-768.zarr")
    sfm = spin_frame_map(bmap, None, 36)
    rng = np.random.default_rng(args.seed)
    cpu = dict.fromkeys(("search", *METHODS), 0.0)
    for _ in range(args.draws):
        _, _, geo, y, _, _, _ = truth_draw(rng, geo_all, truth, "")
        t0 = time.process_time()
        res = spin_axis_search(bmap, sfm, geo, y, [f"b{j}" for j in range(y.shape[1])], 4.0)
        cpu["search"] += time.process_time() - t0
        g = dataclasses.replace(geo, period_s=res.refined_period_s)
        for m in METHODS:
            t0 = time.process_time()
            axis_confidence(
                bmap, g, y, None, res.refined, res.error.T, res.dec_deg, res.ra_deg,
                method=m,
            )  # fmt: skip
            cpu[m] += time.process_time() - t0
    per = ", ".join(f"{k} {v / args.draws:.2f}" for k, v in cpu.items())
    print(f"CPU s per draw over {args.draws} (load {os.getloadavg()[0]:.1f}): {per}")


if __name__ == "__main__":
    main()
