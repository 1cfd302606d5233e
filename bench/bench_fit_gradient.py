"""From how far each roughness fit converges: ``--method gradient`` against SLSQP.

Run: ``PYTHONPATH=src .venv/bin/python bench/bench_fit_gradient.py [--quick]``

The spinning cube of the tests (``tests/estimate/data/spinning_cube.yaml``, four glinting
side faces, 2 bands) with a finer time step (0.1 s, 601 epochs: the narrowest glint, alpha
0.03, lasts about 0.15 s) is simulated with a known roughness and Poisson noise (seed 3),
then fitted from starts a factor 2, 5, 10 and 30 away from the truth, without the 7-point
scan of the SLSQP fit (``scan=False``), by

* ``slsqp``: bounded SLSQP on log chi2 with central-difference gradients (each a pair of
  full simulations on the fixed geometry);
* ``gradient``: trust-region least squares over log roughness with the analytic Jacobian
  (one render pass gives rates and Jacobian).

Cases: one Beckmann material (all faces), truth 0.03 (starts above: 0.06 ... 0.9) and truth
0.3 (starts below: 0.15 ... 0.01); two materials (+x face Beckmann, the others GGX), truths
0.03 and 0.3, each started a factor f away towards the middle of the bounds. A fit counts as
converged when it says so and every roughness is within 3 fitted std (and 1 %) of its truth.
"Simulations": distinct roughness values simulated (SLSQP) or render passes (gradient),
the final std and the chi2 profile check included; the first simulation at the start (the
geometry) is not counted for either.

``--cost``: the cost of one render pass with derivatives against one simulation on the same
geometry, for the ``box-wing`` example (600 epochs, 256 px) with its plastic bus and wings
made Beckmann (bus, gold) and GGX (wings, silica), three rough materials; and for the
articulated ``starlink-v1.5`` example (128 px) with its array made GGX, without and with
Earthshine (64 cells).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

import numpy as np

from speclight.estimate import MeasuredLightCurve, fit_scenario
from speclight.scenario import parse_scenario
from speclight.simulation import simulate

CUBE = Path(__file__).parent.parent / "tests" / "estimate" / "data" / "spinning_cube.yaml"
ONE = '"*": {bsdf: beckmann, roughness: 0.12, reflectance: 0.6}'
TWO = (
    '"+x": {bsdf: beckmann, roughness: A0, reflectance: 0.6}\n'
    '    "*": {bsdf: ggx, roughness: A1, reflectance: 0.5}'
)
FACTORS = (2, 5, 10, 30)


def scenario_text(alphas: list[float]) -> str:
    text = CUBE.read_text().replace("step_s: 0.25", "step_s: 0.1")
    if len(alphas) == 1:
        return text.replace(ONE, ONE.replace("0.12", repr(alphas[0])))
    return text.replace(ONE, TWO.replace("A0", repr(alphas[0])).replace("A1", repr(alphas[1])))


def measured(alphas: list[float]) -> MeasuredLightCurve:
    ds = simulate(parse_scenario(scenario_text(alphas), source="truth")).dataset
    rate = ds["count_rate_measured"].transpose("time", "band").values
    n = ds.sizes["time"]
    return MeasuredLightCurve(ds["time"].values, ["B", "R"], rate, None, np.ones(n, np.int64), "")


def run(truth: list[float], start: list[float], method: str, lc: MeasuredLightCurve) -> str:
    t0 = time.perf_counter()
    fit = fit_scenario(
        parse_scenario(scenario_text(start), source="start"),
        lc,
        free=("albedo", "roughness"),
        method=method,
        scan=False,
    )
    seconds = time.perf_counter() - t0
    got = [fit.roughness[k] for k in fit.roughness]
    ok = fit.converged and all(
        abs(v - t) < max(3 * s, 0) and abs(v - t) < 0.01 * t
        for (v, s), t in zip(got, truth, strict=True)
    )
    values = ", ".join(f"{v:.4g} ± {s:.2g}" for v, s in got)
    starts = ", ".join(f"{a:.3g}" for a in start)
    truths = ", ".join(f"{a:.3g}" for a in truth)
    return (
        f"| {truths} | {starts} | {method} | {'yes' if ok else 'no'} | {values} | "
        f"{fit.extra['n_simulations']} | {seconds:.1f} s |"
    )


def _time_pass(loaded: object, rough: list[str], alpha: list[float]) -> tuple[float, float, Any]:
    """Seconds of one simulation on a fixed geometry and of one render pass (warm)."""
    from speclight.estimate.fitting.roughness_gradient import RoughnessRates

    first = simulate(loaded)  # type: ignore[arg-type]
    use = np.ones(first.geometry.t_s.size, bool)
    rates = RoughnessRates(loaded, first.geometry, rough, use)  # type: ignore[arg-type]
    for _ in range(2):  # the second of each: warm caches
        t0 = time.perf_counter()
        simulate(loaded, geometry=first.geometry)  # type: ignore[arg-type]
        t_sim = time.perf_counter() - t0
        t0 = time.perf_counter()
        rates(np.array(alpha))
        t_pass = time.perf_counter() - t0
    return t_sim, t_pass, rates.reflection


def cost() -> None:
    from speclight.scenario import load_example
    from speclight.scenario.overrides import replace_fields

    rough = ["bus", "wing_+y", "wing_-y"]
    values: dict[str, object] = {"instrument.noise": None}
    values["target.materials.bus"] = {"bsdf": "beckmann", "roughness": 0.3,
                                      "reflectance": {"conductor": "Au"}}  # fmt: skip
    for wing in rough[1:]:
        values[f"target.materials.{wing}"] = {"bsdf": "ggx", "roughness": 0.05,
                                              "reflectance": {"dielectric": "SiO2"}}  # fmt: skip
    loaded = replace_fields(load_example("box-wing"), values)
    t_sim, t_pass, refl = _time_pass(loaded, rough, [0.3, 0.05, 0.05])
    print(f"box-wing, {refl.lit.size} lit epochs, 256 px, variant {refl.session.variant}: "
          f"simulation {t_sim:.2f} s, render pass with 3 derivatives {t_pass:.2f} s")  # fmt: skip
    array = {"bsdf": "ggx", "roughness": 0.1, "reflectance": 0.3}
    for earthshine in (None, {"albedo": 0.3, "samples": 64}):
        values = {"target.materials.array": array, "illumination.earthshine": earthshine}
        loaded = replace_fields(load_example("starlink-v1.5"), values)
        t_sim, t_pass, refl = _time_pass(loaded, ["array"], [0.1])
        cells = 0 if refl.cells is None else refl.cells.epoch.size
        print(f"starlink-v1.5 (GGX array), {refl.lit.size} lit epochs, 128 px, Earthshine "
              f"renders {cells}: simulation {t_sim:.2f} s, render pass {t_pass:.2f} s")  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="factors 2 and 30 only")
    parser.add_argument(
        "--cost", action="store_true", help="cost of a pass (box-wing, starlink-v1.5)"
    )
    args = parser.parse_args()
    if args.cost:
        cost()
        return
    factors = (2, 30) if args.quick else FACTORS
    print("| truth α | start α | method | converged | fitted α ± std | simulations | time |")
    print("|---|---|---|---|---|---|---|")
    cases: list[tuple[list[float], list[float]]] = []
    for f in factors:
        cases.append(([0.03], [0.03 * f]))
    for f in factors:
        cases.append(([0.3], [0.3 / f]))
    for f in factors:
        cases.append(([0.03, 0.3], [0.03 * f, 0.3 / f]))
    data: dict[tuple[float, ...], MeasuredLightCurve] = {}
    for truth, start in cases:
        if tuple(truth) not in data:
            data[tuple(truth)] = measured(truth)
        for method in ("slsqp", "gradient"):
            print(run(truth, start, method, data[tuple(truth)]), flush=True)


if __name__ == "__main__":
    main()
