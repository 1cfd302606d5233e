"""Benchmark ``speclight compare``: 1,000 observations from 10 sites (issue 13: < 60 s on
2 cores).

Run: ``.venv/bin/python bench/bench_compare.py [--example box-wing] [--sites 10]
[--per-site 100]``

The built-in example's pass, seen from 10 sites within about 1 deg of its observer (so the
target is up at every site), every site observing at ``--per-site`` epochs spread over the
pass in two bands (one of the scenario's and the speclite filter ``sdss2010-r``, which
compare adds). Prints the wall-clock time of the whole command (reading, one simulation
per site, the dataset and the statistics) and the time per observation.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import speclight
from speclight.scenario import example_text


def observations_csv(example: str, sites: int, per_site: int, path: Path) -> int:
    loaded = speclight.load(example)
    sc = loaded.scenario
    band = sc.instrument.bands[len(sc.instrument.bands) // 2].name
    start = np.datetime64(sc.time.start.replace(tzinfo=None), "ms")
    span_ms = int((sc.time.stop - sc.time.start).total_seconds() * 1e3)
    rng = np.random.default_rng(0)
    rows = ["time,latitude_deg,longitude_deg,altitude_m,magnitude,magnitude_sigma,band"]
    for k in range(sites):
        lat = sc.observer.latitude_deg + 0.3 * (k % 4) - 0.45
        lon = sc.observer.longitude_deg + 0.4 * (k // 4) - 0.4
        offsets = np.sort(rng.choice(span_ms, size=per_site // 2, replace=False))
        for t in start + offsets.astype("timedelta64[ms]"):
            for b in (band, "sdss2010-r"):
                mag = 8.0 + rng.normal(0, 0.3)
                rows.append(f"{t}Z,{lat:.4f},{lon:.4f},300,{mag:.3f},0.05,{b}")
    path.write_text("\n".join(rows) + "\n")
    return len(rows) - 1


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--example", default="box-wing")
    parser.add_argument("--sites", type=int, default=10)
    parser.add_argument("--per-site", type=int, default=100)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        scenario = folder / "scenario.yaml"
        scenario.write_text(example_text(args.example))
        obs = folder / "obs.csv"
        n = observations_csv(args.example, args.sites, args.per_site, obs)
        speclight_cli = Path(sys.executable).with_name("speclight")
        cmd = [str(speclight_cli), "compare", str(scenario), str(obs), "-o", str(folder / "c.nc")]
        t0 = time.perf_counter()
        done = subprocess.run(cmd, capture_output=True, text=True, check=False)
        seconds = time.perf_counter() - t0
        print(done.stdout.strip() or done.stderr.strip())
        print(
            f"{args.example}: {n} observations from {args.sites} sites: {seconds:.1f} s "
            f"({1e3 * seconds / n:.1f} ms per observation), exit code {done.returncode}"
        )


if __name__ == "__main__":
    main()
