"""Peak memory of a single-mode box-wing run (3 plastics, 3,271 render channels) against the
up-front estimate, with and without its channel weights.

    python bench/bench_memory_channels.py RESOLUTION_PX STEP_S

The box-wing example's 10-minute window at ``STEP_S`` (0.06 s: 9,984 epochs); prints the
process's peak RSS (``ru_maxrss``) after the dataset is serialised and the estimate of
``speclight.simulation.memory``. One run per fresh process (BENCHMARKS.md, Memory).
"""

from __future__ import annotations

import resource
import sys

import yaml

from speclight.io.netcdf import dataset_bytes
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import memory, simulate

MIB = 1024**2


def main(resolution_px: int, step_s: float) -> None:
    d = yaml.safe_load(example_text("box-wing"))
    d["render"]["resolution_px"] = resolution_px
    d["time"]["step_s"] = step_s
    loaded = parse_scenario(yaml.safe_dump(d), source="bench")
    n = memory.grid_epochs(loaded.scenario)
    est = memory.estimate_memory(loaded.scenario, n, loaded.resolve)
    dataset_bytes(simulate(loaded).dataset)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    without = (est.total_bytes - est.parts["channels"]) / MIB
    print(
        f"{n} epochs at {resolution_px} px: peak {peak:.0f} MiB; estimate "
        f"{est.total_bytes / MIB:.0f} MiB ({without:.0f} MiB without the channel weights)"
    )


if __name__ == "__main__":
    main(int(sys.argv[1]), float(sys.argv[2]))
