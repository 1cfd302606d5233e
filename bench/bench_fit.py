"""Benchmark ``speclight fit`` and print the shape of the reference paper's Table 2.

Run: ``PYTHONPATH=src .venv/bin/python bench/bench_fit.py [--no-roughness]``

Simulates the built-in ``calsphere`` and ``lcs1`` examples, fits each scenario to its own
noisy output (``count_rate_measured``: calsphere's albedos; lcs1's albedos and Beckmann
roughness, from the example's roughness 0.05 and from 0.3), and prints the fitted band
albedos in a table shaped as Table 2 of Nussbaum et al. (2022), with the wall-clock time of
each fit (its simulations included, not the run that made the data). The last row fits the
spinning Beckmann cube of the tests (``tests/estimate/data/spinning_cube.yaml``, roughness
0.12, started at 0.3), whose glints do constrain the roughness.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from speclight.estimate import FitResult, MeasuredLightCurve, fit_scenario
from speclight.scenario import LoadedScenario, example_text, load_example, parse_scenario
from speclight.simulation import simulate

CUBE = Path(__file__).parent.parent / "tests" / "estimate" / "data" / "spinning_cube.yaml"
COLUMNS = ["R", "G", "B", "SPAD-950", "SPAD-650", "SPAD-420"]  # Table 2's order


def measured_of(loaded: LoadedScenario) -> MeasuredLightCurve:
    ds = simulate(loaded).dataset
    rate = ds["count_rate_measured"].transpose("time", "band").values
    bands = [str(b) for b in ds["band"].values]
    n = ds.sizes["time"]
    return MeasuredLightCurve(ds["time"].values, bands, rate, None, np.ones(n, np.int64), "sim")


def timed_fit(
    loaded: LoadedScenario, lc: MeasuredLightCurve, free: tuple[str, ...]
) -> tuple[FitResult, float]:
    start = time.perf_counter()
    result = fit_scenario(loaded, lc, free=free)
    return result, time.perf_counter() - start


def row(name: str, model: str, result: FitResult, seconds: float) -> str:
    rough = "-"
    for value, std in result.roughness.values():
        rough = f"{value:.3f} ± {std:.2g}" if np.isfinite(std) else f"{value:.3f} (not constrained)"
    cells = []
    for band in COLUMNS:
        j = result.band_names.index(band) if band in result.band_names else None
        cells.append("-" if j is None else f"{result.albedo[j]:.3f}")
    flag = "yes" if result.converged else "no"
    return (
        f"| {name} | {model} | {rough} | {' | '.join(cells)} | {result.rms_percent_of_mean:.2f} "
        f"| {result.rms_percent_of_total:.2g} | {flag} | {seconds:.1f} s |"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--no-roughness", action="store_true", help="albedos only for lcs1")
    args = parser.parse_args()
    lines = [
        f"| satellite | model | roughness α | {' | '.join(COLUMNS)} | RMS % of mean "
        "| RMS % of total | converged | fit time |",
        "|" + "---|" * (len(COLUMNS) + 7),
    ]
    notes = []
    cal = load_example("calsphere")
    result, seconds = timed_fit(cal, measured_of(cal), ("albedo",))
    lines.append(row("Calsphere 4A (example, truth 0.9)", "Lambertian", result, seconds))
    lcs = load_example("lcs1")
    free = ("albedo",) if args.no_roughness else ("albedo", "roughness")
    lc1 = measured_of(lcs)
    result, seconds = timed_fit(lcs, lc1, free)
    lines.append(row("LCS 1 (example, truth Al, α 0.05)", "Beckmann", result, seconds))
    notes.append(f"LCS 1: {result.message} ({result.extra.get('n_simulations', 1)} simulations)")
    if not args.no_roughness:
        text = example_text("lcs1").replace("roughness: 0.05", "roughness: 0.3")
        result, seconds = timed_fit(parse_scenario(text, source="lcs1 from 0.3"), lc1, free)
        lines.append(row("LCS 1, started at α 0.3", "Beckmann", result, seconds))
        notes.append(f"LCS 1 from 0.3: {result.message} ({result.extra['n_simulations']} sims)")
    text = CUBE.read_text()
    truth = parse_scenario(text, source="cube truth")
    start = parse_scenario(text.replace("roughness: 0.12", "roughness: 0.3"), source="cube")
    result, seconds = timed_fit(start, measured_of(truth), ("albedo", "roughness"))
    lines.append(row("spinning cube (test, truth 0.6, α 0.12)", "Beckmann", result, seconds))
    notes.append(f"cube: {result.message} ({result.extra.get('n_simulations')} simulations)")
    print("\n".join(lines))
    print("\n".join(notes))


if __name__ == "__main__":
    main()
