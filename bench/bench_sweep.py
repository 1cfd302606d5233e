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

import os

# Dask's workers run BLAS on one thread (distributed.nanny.pre-spawn-environ); so does the
# serial run here, so that both sides do the same work per case (the band integrals no longer
# use BLAS, so the stores are equal bit for bit either way: BENCHMARKS.md, "Sweep")
for _name in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import platform  # noqa: E402
import resource  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import xarray as xr  # noqa: E402

from speclight.scale import open_executor  # noqa: E402
from speclight.scale.sweep_cases import plan_sweep  # noqa: E402
from speclight.scale.sweep_file import load_sweep  # noqa: E402
from speclight.scale.sweep_run import run_sweep  # noqa: E402

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


def _cpu_s() -> float:
    """CPU seconds of this process, all threads (user + system)."""
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


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
        warm = _plan(folder, "warm.yaml", 4 * max(args.workers, 1), args.px)

        run_sweep(warm, folder / "warm-serial.zarr", scheduler="none")
        t, cpu = time.perf_counter(), _cpu_s()
        serial = run_sweep(plan, folder / "serial.zarr", scheduler="none")
        s_serial, cpu_serial = time.perf_counter() - t, _cpu_s() - cpu
        print(
            f"serial: {args.cases} cases in {s_serial:.1f} s, "
            f"{args.cases / s_serial:.2f} cases/s, failed {len(serial.failed)}; CPU "
            f"{cpu_serial / args.cases:.3f} s per case"
        )

        t = time.perf_counter()
        with open_executor("local", n_workers=args.workers) as ex:
            address = ex.client.scheduler.address
            started = time.perf_counter() - t
            t = time.perf_counter()
            run_sweep(warm, folder / "warm-dask.zarr", scheduler=address)
            warmed = time.perf_counter() - t
            print(f"cluster of {args.workers}: start {started:.1f} s, warm-up {warmed:.1f} s")
            t, cpu = time.perf_counter(), _cpu_s()
            before = ex.client.run(_cpu_s)
            dask = run_sweep(plan, folder / "dask.zarr", scheduler=address)
            s_dask = time.perf_counter() - t
            after = ex.client.run(_cpu_s)
            cpu_caller = _cpu_s() - cpu  # client, scheduler, Zarr writes
            cpu_workers = sum(after[w] - before[w] for w in after)
            print(
                f"cluster CPU per case: workers {cpu_workers / args.cases:.3f} s, calling "
                f"process (scheduler, client, writes) {cpu_caller / args.cases:.3f} s"
            )
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
