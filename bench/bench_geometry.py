"""Benchmark: geometry + attitude for one day at 1 s (86,400 epochs), end to end.

Run: .venv/bin/python bench/bench_geometry.py
Goal (issue 2): under 2 s on 2 cores for the whole geometry and attitude stage.
"""

from __future__ import annotations

import time

import yaml

from speclight.scenario import example_text, parse_scenario
from speclight.simulation.geometry_stage import scenario_geometry

ATTITUDES = {
    "spin": {
        "model": "spin",
        "spin_axis_ra_deg": 30.0,
        "spin_axis_dec_deg": 45.0,
        "period_s": 12.0,
    },
    "torque_free": {
        "model": "torque_free",
        "inertia_kg_m2": [10.0, 14.0, 18.0],
        "initial_attitude": {"quaternion": [1.0, 0.0, 0.0, 0.0]},
        "angular_velocity_body_rad_s": [0.05, 0.2, 0.05],
    },
}


def main() -> None:
    base = yaml.safe_load(example_text("lcs1"))
    base["time"] = {"start": "2020-07-18T00:00:00Z", "stop": "2020-07-18T23:59:59Z", "step_s": 1.0}
    scenario_geometry(parse_scenario(yaml.safe_dump(base)))  # warm caches (ephemeris, EOP)
    for name, attitude in ATTITUDES.items():
        base["attitude"] = attitude
        loaded = parse_scenario(yaml.safe_dump(base))
        best = float("inf")
        for _ in range(3):
            t0 = time.perf_counter()
            geo = scenario_geometry(loaded)
            best = min(best, time.perf_counter() - t0)
        print(f"geometry+attitude ({name}): {geo.t_s.size} epochs in {best:.3f} s (best of 3)")


if __name__ == "__main__":
    main()
