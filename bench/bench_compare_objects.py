"""Benchmark one geometry pass of ``speclight compare`` with an ``object`` column and
``orbit: {observed: true}``: the cost the command's day-limit check counts per site and
group of objects seen at overlapping times (``compare_run.SECONDS_PER_GROUP``).

Run: ``.venv/bin/python bench/bench_compare_objects.py [--repeats 5]``

Two satellites seen alternately every 10 s from Stuttgart (the rows of
tests/estimate/test_compare_objects.py: 3 epochs each, two groups), nadir-pointing bus with
an array; prints the least, median and largest time of one group's geometry pass (the
first two passes, which warm up skyfield's tables, left out).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    sys.path.insert(0, str(ROOT / "tests" / "estimate"))
    import test_compare_objects as rows  # the test's observations and scenario

    from speclight.estimate.comparison.compare_geometry import row_groups
    from speclight.estimate.inputs.observations import read_observations
    from speclight.scenario import parse_scenario
    from speclight.scenario.overrides import with_overrides
    from speclight.simulation.geometry_stage import scenario_geometry

    obs = read_observations(rows._rows(Path(tempfile.mkdtemp()), rows.INTERLEAVED))
    loaded = parse_scenario(yaml.safe_dump(rows._scenario(None)))
    lat, lon, alt = rows.STUTTGART_0M
    site = with_overrides(
        loaded,
        {"observer.latitude_deg": lat, "observer.longitude_deg": lon, "observer.altitude_m": alt},
    )
    groups = row_groups(loaded, obs)
    times = []
    for _ in range(args.repeats):
        for g in groups:
            epochs = np.unique(obs.time_utc[g.rows])
            t0 = time.perf_counter()
            scenario_geometry(site, epochs, trajectory=g.trajectory)
            times.append(time.perf_counter() - t0)
    t = np.array(times[2:])
    print(
        f"{len(groups)} groups; one pass of 3 epochs: least {t.min():.4f} s, median "
        f"{np.median(t):.4f} s, largest {t.max():.4f} s"
    )


if __name__ == "__main__":
    main()
