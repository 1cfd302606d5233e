"""Benchmark: the whole built-in box-wing example, end to end (issue 4: < 30 s on 2 cores).

Run: .venv/bin/python bench/bench_pipeline.py [--6s]
Times ``speclight.simulate`` (geometry, single-mode render, atmosphere, instrument) for the
600-epoch box-wing pass with SPECTRL2, and with 6S (cold cache in a fresh folder, then warm).
"""

from __future__ import annotations

import os
import sys
import tempfile
import time

import yaml

from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate


def _run(text: str) -> float:
    t0 = time.perf_counter()
    ds = simulate(parse_scenario(text)).dataset
    elapsed = time.perf_counter() - t0
    print(
        f"  {ds.sizes['time']} epochs x {ds.sizes['wavelength']} bins, "
        f"variant {ds.attrs.get('render_variant')}: {elapsed:.2f} s"
    )
    return elapsed


def main() -> None:
    data = yaml.safe_load(example_text("box-wing"))
    print("box-wing, spectrl2 (first run includes kernel compilation and table loading):")
    _run(yaml.safe_dump(data))
    _run(yaml.safe_dump(data))
    if "--6s" in sys.argv:
        data["atmosphere"] = {"model": "6s"}
        with tempfile.TemporaryDirectory() as cache:
            os.environ["SPECLIGHT_CACHE_DIR"] = cache
            print("box-wing, 6s cold cache:")
            _run(yaml.safe_dump(data))
            print("box-wing, 6s warm cache:")
            _run(yaml.safe_dump(data))


if __name__ == "__main__":
    main()
