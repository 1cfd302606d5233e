"""Sweep benchmark (issue 12): cases per second on a local Dask cluster against serial.

Run: ``.venv/bin/python bench/bench_sweep.py [--cases 1000] [--workers 2] [--px 64]``

The built-in calsphere example (7 bands, its 481-epoch pass, single mode at ``--px``) with
its albedo drawn uniformly in [0.1, 0.9] ``--cases`` times (``draws``), run:

1. serial, in this process (``--scheduler none``), after one warm-up case (imports, the
   render backend's first compilation);
2. on a local cluster of ``--workers`` workers, started before and warmed up with one case
   per worker, so that both figures are the steady rate; the cluster's start and warm-up
   are reported apart;

and the two stores compared (the cluster must give the serial arrays). Also: the time to
check and expand the sweep file (every case's scenario validated) and the peak resident
memory of this process (the serial run) and of each worker.
"""

from __future__ import annotations

import argparse
import os
import platform
import resource
import tempfile
import time
from pathlib import Path

import numpy as np
import xarray as xr

from speclight.scale import open_executor
from speclight.scale.sweep_cases import plan_sweep
from speclight.scale.sweep_file import load_sweep
from speclight.scale.sweep_run import run_sweep

SWEEP = """base: calsphere
set: {{render.resolution_px: {px}}}
vary:
  target.materials.body.reflectance: {{uniform: [0.1, 0.9]}}
draws: {draws}
seed: 12
"""


def _plan(folder: Path, name: str, draws: int, px: int):  # type: ignore[no-untyped-def]
    path = folder / name
    path.write_text(SWEEP.format(px=px, draws=draws))
    return plan_sweep(load_sweep(path))


def _peak_rss_gib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024**2


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=1000)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--px", type=int, default=64)
    args = parser.parse_args()
    print(f"{platform.machine()}, {os.cpu_count()} cores, load {os.getloadavg()}")
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        t = time.perf_counter()
        plan = _plan(folder, "sweep.yaml", args.cases, args.px)
        print(f"check and expand {args.cases} cases: {time.perf_counter() - t:.2f} s")
        warm = _plan(folder, "warm.yaml", max(args.workers, 1), args.px)

        run_sweep(warm, folder / "warm-serial.zarr", scheduler="none")
        t = time.perf_counter()
        serial = run_sweep(plan, folder / "serial.zarr", scheduler="none")
        s_serial = time.perf_counter() - t
        print(
            f"serial: {args.cases} cases in {s_serial:.1f} s, "
            f"{args.cases / s_serial:.2f} cases/s, failed {len(serial.failed)}"
        )

        t = time.perf_counter()
        with open_executor("local", n_workers=args.workers) as ex:
            address = ex.client.scheduler.address
            started = time.perf_counter() - t
            t = time.perf_counter()
            run_sweep(warm, folder / "warm-dask.zarr", scheduler=address)
            warmed = time.perf_counter() - t
            print(f"cluster of {args.workers}: start {started:.1f} s, warm-up {warmed:.1f} s")
            t = time.perf_counter()
            dask = run_sweep(plan, folder / "dask.zarr", scheduler=address)
            s_dask = time.perf_counter() - t
            peaks = ex.client.run(_peak_rss_gib).values()
            print(f"peak resident memory per worker: {', '.join(f'{p:.2f}' for p in peaks)} GiB")
        print(
            f"cluster: {args.cases} cases in {s_dask:.1f} s, {args.cases / s_dask:.2f} "
            f"cases/s, failed {len(dask.failed)}; ratio cluster/serial "
            f"{s_serial / s_dask:.2f}x; load {os.getloadavg()}"
        )
        a = xr.open_zarr(folder / "serial.zarr")["count_rate"].values
        b = xr.open_zarr(folder / "dask.zarr")["count_rate"].values
        print(f"stores identical: {np.array_equal(a, b, equal_nan=True)}")
    print(f"peak resident memory of this process: {_peak_rss_gib():.2f} GiB")


if __name__ == "__main__":
    main()
