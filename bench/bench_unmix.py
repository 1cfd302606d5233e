"""Unmixing benchmark: run ``python bench/bench_unmix.py [--epochs N]`` and read the printout.

Synthetic mixtures of 4 random endmember signatures over 10 bands with Gaussian noise
(10,000 epochs by default): the time of :func:`speclight.estimate.spectra.unmixing.unmix` for every
method and of :func:`speclight.estimate.spectra.endmembers.extract_endmembers` for every method
(best of three runs each). The issue's target: every unmixing method under 1 s.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from collections.abc import Callable
from functools import partial

import numpy as np

from speclight.estimate.spectra.endmembers import extract_endmembers
from speclight.estimate.spectra.unmixing import unmix

TARGET_S = 1.0


def best_of(fn: Callable[[], object], repeat: int = 3) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--epochs", type=int, default=10_000)
    parser.add_argument("--bands", type=int, default=10)
    parser.add_argument("--endmembers", type=int, default=4)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    s = rng.uniform(0.05, 0.9, size=(args.endmembers, args.bands))
    a = rng.dirichlet(np.ones(args.endmembers), size=args.epochs)
    x = a @ s + rng.normal(0.0, 0.01, size=(args.epochs, args.bands))
    print(
        f"python {platform.python_version()}, numpy {np.__version__}, {os.cpu_count()} cores; "
        f"{args.epochs} epochs x {args.bands} bands x {args.endmembers} endmembers"
    )
    for method in ("ls", "nnls", "nnls-norm", "fcls"):
        t = best_of(partial(unmix, x, s, method))
        flag = "ok" if t < TARGET_S else f"OVER the {TARGET_S:.0f} s target"
        print(f"unmix {method:10s} {t:8.4f} s  {flag}")
    for method in ("atgp", "pca", "nfindr"):
        t = best_of(partial(extract_endmembers, x, args.endmembers, method))
        print(f"extract_endmembers {method:7s} {t:8.4f} s")


if __name__ == "__main__":
    main()
