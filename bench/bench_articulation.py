"""Cost of articulated parts: the starlink-v1.5 pass rendered with its Sun-tracking array.

Run: ``PYTHONPATH=src .venv/bin/python bench/bench_articulation.py``

Times the render stage (best of 2) of 300 epochs at 1 s, 128 px, for: no articulation (the
array fixed as built: one scene), articulation_step_deg 0.25 (the example's), 1.0, and 0
(exact angles: one scene per epoch); prints the number of distinct poses and the largest
magnitude difference (median, max) from the exact render at 540-550 nm.
"""

from __future__ import annotations

import time

import numpy as np

import speclight
from speclight.render.articulated import pose_groups
from speclight.simulation.geometry_stage import scenario_geometry
from speclight.simulation.reflection import build_joints, build_target, render_reflection

BASE = {
    "time.start": "2024-03-20T23:56:00Z",
    "time.stop": "2024-03-21T00:00:59Z",
    "time.step_s": 1.0,
}


def run(overrides: dict[str, object]) -> tuple[float, np.ndarray, int]:
    loaded = speclight.with_overrides(speclight.load("starlink-v1.5"), {**BASE, **overrides})
    geo = scenario_geometry(loaded)
    wl = np.array([540.0, 550.0])
    poses = 1
    if loaded.scenario.target.articulation:
        target = build_target(loaded)
        joints = build_joints(loaded, target)
        a = np.stack([j.angles_rad(geo.sun_direction_body, geo.time_utc) for j in joints], 1)
        poses = len(pose_groups(a, loaded.scenario.target.articulation_step_deg)[0])
    best, out = np.inf, None
    for _ in range(2):
        t0 = time.perf_counter()
        refl = render_reflection(loaded, geo, wl)
        best = min(best, time.perf_counter() - t0)
        out = refl.intensity_W_sr_nm[:, 0]
    return best, out, poses


def main() -> None:
    cases = {
        "fixed array (no articulation)": {"target.articulation": {}},
        "step 1.0 deg": {"target.articulation_step_deg": 1.0},
        "step 0.25 deg (example)": {"target.articulation_step_deg": 0.25},
        "exact (step 0)": {"target.articulation_step_deg": 0.0},
    }
    results = {k: run(v) for k, v in cases.items()}
    exact = results["exact (step 0)"][1]
    for k, (t, inten, poses) in results.items():
        ok = (exact > 0) & (inten > 0)
        dm = np.abs(2.5 * np.log10(inten[ok] / exact[ok]))
        print(
            f"{k:32s} {t:7.2f} s  {poses:4d} poses  |dm| vs exact: median {np.median(dm):.4f}, "
            f"max {dm.max():.4f} mag"
        )


if __name__ == "__main__":
    main()
