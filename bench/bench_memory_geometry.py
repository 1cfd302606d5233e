"""Peak memory of a geometry-only run (calsphere without its target) of N epochs.

    python bench/bench_memory_geometry.py N

Prints the epochs, the in-memory NetCDF size and the process's peak RSS (``ru_maxrss``)
after the dataset is serialised; run one N per fresh process (BENCHMARKS.md, Memory).
"""

from __future__ import annotations

import resource
import sys

import yaml

from speclight.io.netcdf import dataset_bytes
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate

WINDOW_S = 259_200.0  # three days


def main(n_epochs: int) -> None:
    d = yaml.safe_load(example_text("calsphere"))
    d.pop("target")
    d["time"] = {
        "start": "2020-02-29T21:13:00Z",
        "stop": "2020-03-03T21:13:00Z",
        "step_s": WINDOW_S / (n_epochs - 1),
    }
    result = simulate(parse_scenario(yaml.safe_dump(d), source="bench"))
    size_mb = len(dataset_bytes(result.dataset)) / 1e6
    peak_mib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"{result.dataset.sizes['time']} epochs: file {size_mb:.1f} MB, peak {peak_mib:.0f} MiB")


if __name__ == "__main__":
    main(int(sys.argv[1]))
