"""Start-up of the command line: import time of `simulate --example calsphere` and `--help`.

Each run is a fresh interpreter with ``-X importtime``; the start-up is the sum of the
top-level imports' cumulative times (everything imported, whenever it is imported: the
modules a command loads lazily count too; an import that failed, such as the ``distributed``
that the NetCDF writer keeps out, does not), beside the run's wall time. On a loaded machine
those wall-clock figures grow with the load, so the same modules are then imported again, in
the same order, in a fresh interpreter that reports the CPU time it took (user + system):
the import CPU time, which the load barely changes. Runs alternate between the given source
trees (``--src`` twice compares two checkouts under the same load) and the median of
``--repeat`` runs is reported.

Modules are imported from bytecode, as an installed package is (pip compiles it at install
time): the runs write and read their bytecode in a temporary folder
(``PYTHONPYCACHEPREFIX``), so no source tree is written to, and one unmeasured run per tree
fills it first. Where ``PYTHONDONTWRITEBYTECODE`` is set (it is on the project's build
machines) an editable install compiles all of speclight from source on every run instead
(about 0.1 s more CPU); ``--compile-each-run`` measures that case.

    python bench/bench_startup.py --repeat 5
    python bench/bench_startup.py --src /path/to/old/src --src src --repeat 7
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

COMMANDS = {
    "simulate --example calsphere": ["simulate", "--example", "calsphere", "-q", "--force"],
    "--help": ["--help"],
}


def import_seconds(stderr: str, loaded: set[str]) -> tuple[float, dict[str, float]]:
    """Sum of the top-level imports' cumulative times [s], and each of them, counting only
    the modules in ``loaded`` (the run's modules: not an import that failed)."""
    total, top = 0.0, {}
    for line in stderr.splitlines():
        if not line.startswith("import time:") or "|" not in line:
            continue
        _, cumulative, name = line.split("|", 2)
        top_level = name.startswith(" ") and not name.startswith("  ")
        if top_level and name.strip() in loaded and cumulative.strip().isdigit():
            seconds = int(cumulative) * 1e-6
            total += seconds
            top[name.strip()] = seconds
    return total, top


#: Runs the command line as ``python -m speclight`` does, then lists the modules it loaded
#: (an import that failed, such as the ``distributed`` that the writer keeps out, is not one).
_RUN_LISTING_MODULES = """
import atexit, os, runpy, sys
def _listing():
    with open(os.environ["SPECLIGHT_BENCH_MODULES"], "w") as f:
        f.write("\\n".join(k for k, m in sys.modules.items() if m is not None))
atexit.register(_listing)
sys.argv = ["speclight", *sys.argv[1:]]
runpy.run_module("speclight", run_name="__main__", alter_sys=True)
"""

_IMPORT_CPU = """
import importlib, resource, sys
for name in sys.argv[1:]:
    try:
        importlib.import_module(name)
    except Exception:  # a module that needs its caller's set-up (a Mitsuba variant)
        pass
use = resource.getrusage(resource.RUSAGE_SELF)
print(use.ru_utime + use.ru_stime)
"""


#: The environment of the measured runs (:func:`main` sets where bytecode is kept).
_ENV = dict(os.environ)


def import_cpu_seconds(src: str, modules: list[str]) -> float:
    """CPU time [s] of a fresh interpreter importing ``modules`` in order (start included)."""
    env = dict(_ENV, PYTHONPATH=src)
    run = subprocess.run(
        [sys.executable, "-c", _IMPORT_CPU, *modules],
        env=env,
        capture_output=True,
        text=True,
        check=True,
    )
    return float(run.stdout.strip().splitlines()[-1])


def one_run(src: str, args: list[str], out: Path) -> tuple[float, float, float, dict[str, float]]:
    listing = out.with_suffix(".modules")
    env = dict(_ENV, PYTHONPATH=src, SPECLIGHT_BENCH_MODULES=str(listing))
    extra = ["-o", str(out)] if args[0] == "simulate" else []
    start = time.perf_counter()
    run = subprocess.run(
        [sys.executable, "-X", "importtime", "-c", _RUN_LISTING_MODULES, *args, *extra],
        env=env,
        capture_output=True,
        text=True,
        check=True,
    )
    wall = time.perf_counter() - start
    loaded = set(listing.read_text().split())
    total, top = import_seconds(run.stderr, loaded)
    return wall, total, import_cpu_seconds(src, list(top)), top


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--src", action="append", help="source tree(s) (default: ./src)")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument(
        "--compile-each-run",
        action="store_true",
        help="keep the environment's PYTHONDONTWRITEBYTECODE (speclight compiled on every run)",
    )
    opts = parser.parse_args()
    sources = [str(Path(s).resolve()) for s in (opts.src or ["src"])]
    print(f"load average: {os.getloadavg()[0]:.2f} (1 min), {os.cpu_count()} cores")
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "calsphere.nc"
        if opts.compile_each_run:
            print("bytecode: as the environment says (PYTHONDONTWRITEBYTECODE kept)")
        else:
            _ENV.pop("PYTHONDONTWRITEBYTECODE", None)
            _ENV["PYTHONPYCACHEPREFIX"] = str(Path(tmp) / "bytecode")
            for src in sources:  # unmeasured: fills the bytecode folder
                one_run(src, COMMANDS["simulate --example calsphere"], out)
        for label, args in COMMANDS.items():
            results: dict[str, list[tuple[float, float, float, dict[str, float]]]] = {}
            for _ in range(opts.repeat):
                for src in sources:
                    results.setdefault(src, []).append(one_run(src, args, out))
            for src, runs in results.items():
                wall = statistics.median(r[0] for r in runs)
                imports = statistics.median(r[1] for r in runs)
                cpu = statistics.median(r[2] for r in runs)
                slowest = sorted(runs[-1][3].items(), key=lambda kv: -kv[1])[:6]
                print(
                    f"{label:30s} {src}: import CPU {cpu:.2f} s, imports (wall) {imports:.2f} s,"
                    f" run wall {wall:.2f} s"
                )
                print("    largest:", ", ".join(f"{k} {v:.2f}" for k, v in slowest))


if __name__ == "__main__":
    main()
