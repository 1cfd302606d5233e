"""Calibration of ``speclight fit`` over blind draws (issue 25): are its sigmas honest?

Run: ``PYTHONPATH=src .venv/bin/python bench/bench_calibration_fit.py [--draws 50]
[--kind albedo|roughness|both] [--seed 0]``

Each draw chooses the truth, the geometry, the noise and the start at random (seeded), makes
the measurements with ``speclight simulate`` (``count_rate_measured``: shot noise, sky, dark
current and read noise; no sigma given, as a user's CSV without ``_sigma`` columns), and fits
them with the default method from the start:

* **albedo**: the Lambertian ``calsphere`` example at 32 px; reflectance ~ U(0.1, 0.95), a
  window of 30-180 s anywhere in the lit part of the pass above 10 deg, fitted from 0.4
  (``--free albedo``);
* **roughness**: the spinning Beckmann cube of the tests (``tests/estimate/data/
  spinning_cube.yaml``, 24 px, 0.5 s exposures over one minute); roughness ~ logU(0.04, 0.4),
  reflectance ~ U(0.2, 0.9), spin period ~ U(20, 45) s, initial phase ~ U(0, 360) deg, window
  shifted by U(-120, 120) s, fitted from a roughness ~ logU(0.01, 1) (``--free
  albedo,roughness``);
* **faces** (``--kind faces``, not in ``both``): that cube with a material per face, each
  face's roughness drawn on its own, all started from one value; the ``+z`` and ``-z`` faces
  (along the spin axis) never glint, and the fit must say that it cannot constrain them.

It prints, per kind, the fraction recovered (converged, and within 3 reported sigmas of the
truth), the standard deviation and the median absolute value of the pulls ``(estimate -
truth) / sigma`` (a calibrated sigma gives 1 and 0.67), and what the fit said where it did not
converge.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from speclight.estimate import FitResult, MeasuredLightCurve, fit_scenario
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate

CUBE = Path(__file__).parent.parent / "tests" / "estimate" / "data" / "spinning_cube.yaml"


def measured_of(d: dict[str, Any]) -> MeasuredLightCurve:
    ds = simulate(parse_scenario(yaml.safe_dump(d), source="truth")).dataset
    rate = ds["count_rate_measured"].transpose("time", "band").values
    bands = [str(b) for b in ds["band"].values]
    n = ds.sizes["time"]
    return MeasuredLightCurve(ds["time"].values, bands, rate, None, np.ones(n, np.int64), "sim")


def _shift(iso: str, seconds: float) -> str:
    t = np.datetime64(iso.rstrip("Z"), "ms") + np.timedelta64(int(seconds * 1000), "ms")
    return str(t) + "Z"


def albedo_draw(rng: np.random.Generator) -> tuple[dict, dict, tuple[str, ...], dict]:
    d = yaml.safe_load(example_text("calsphere"))
    truth = float(rng.uniform(0.1, 0.95))
    length = float(rng.uniform(30.0, 180.0))  # lit and above 10 deg from 125 s to 315 s
    offset = float(rng.uniform(125.0, 315.0 - length))
    start = d["time"]["start"].isoformat().replace("+00:00", "Z")
    d["time"].update(start=_shift(start, offset), stop=_shift(start, offset + length))
    d["render"]["resolution_px"] = 32
    d["instrument"]["noise"]["seed"] = int(rng.integers(1 << 30))
    d["target"]["materials"]["body"]["reflectance"] = truth
    fit = yaml.safe_load(yaml.safe_dump(d))
    fit["target"]["materials"]["body"]["reflectance"] = 0.4
    return d, fit, ("albedo",), {"albedo": truth}


def roughness_draw(rng: np.random.Generator) -> tuple[dict, dict, tuple[str, ...], dict]:
    d = yaml.safe_load(CUBE.read_text())
    alpha = float(np.exp(rng.uniform(np.log(0.04), np.log(0.4))))
    albedo = float(rng.uniform(0.2, 0.9))
    shift = float(rng.uniform(-120.0, 120.0))
    d["time"].update(
        start=_shift("2020-07-18T01:25:00Z", shift),
        stop=_shift("2020-07-18T01:26:00Z", shift),
        step_s=0.5,
    )
    d["instrument"]["exposure_s"] = 0.5
    d["instrument"]["noise"]["seed"] = int(rng.integers(1 << 30))
    d["attitude"].update(
        period_s=float(rng.uniform(20.0, 45.0)), initial_phase_deg=float(rng.uniform(0, 360))
    )
    d["target"]["materials"]["*"].update(roughness=alpha, reflectance=albedo)
    fit = yaml.safe_load(yaml.safe_dump(d))
    start = float(np.exp(rng.uniform(np.log(0.01), np.log(1.0))))
    fit["target"]["materials"]["*"].update(roughness=start, reflectance=0.5)
    return d, fit, ("albedo", "roughness"), {"albedo": albedo, "roughness": alpha, "start": start}


FACES = ("+x", "-x", "+y", "-y", "+z", "-z")


def faces_draw(rng: np.random.Generator) -> tuple[dict, dict, tuple[str, ...], dict]:
    """The cube of :func:`roughness_draw` with a material per face, each face's roughness
    drawn on its own; the four side faces glint, ``+z`` and ``-z`` (along the spin axis)
    never do."""
    d, fit, free, truth = roughness_draw(rng)
    material = d["target"]["materials"].pop("*")
    alphas = np.exp(rng.uniform(np.log(0.04), np.log(0.4), len(FACES)))
    d["target"]["materials"] = {f: {**material, "roughness": float(a)} for f, a in
                                zip(FACES, alphas, strict=True)}  # fmt: skip
    start = fit["target"]["materials"].pop("*")
    fit["target"]["materials"] = {f: dict(start) for f in FACES}
    truth["roughness"] = dict(zip(FACES, alphas, strict=True))
    return d, fit, free, truth


def _pull(error: Any, std: Any) -> np.ndarray:
    """error / std where std is a finite positive sigma; NaN where no sigma is claimed."""
    e, s = np.asarray(error, dtype=float), np.asarray(std, dtype=float)
    ok = np.isfinite(s) & (s > 0)
    return np.where(ok, e / np.where(ok, s, 1.0), np.nan)


def pulls(result: FitResult, truth: dict) -> dict[str, np.ndarray]:
    out = {"albedo": _pull(result.albedo - truth["albedo"], result.albedo_std)}
    rough = truth.get("roughness")
    values = [
        float(_pull(v - (rough[name] if isinstance(rough, dict) else rough), s))
        for name, (v, s) in result.roughness.items()
    ]
    if values:
        out["roughness"] = np.array(values)
    return out


def run(kind: str, draw: Callable, n: int, rng: np.random.Generator) -> None:
    print(f"\n### {kind}: {n} draws\n")
    print("| draw | truth | start | estimate | pull | converged | s | said |")
    print("|---|---|---|---|---|---|---|---|")
    found: dict[str, list[float]] = {"albedo": [], "roughness": []}
    recovered, said = 0, []
    for k in range(n):
        d, start, free, truth = draw(rng)
        lc = measured_of(d)
        t0 = time.perf_counter()
        result = fit_scenario(parse_scenario(yaml.safe_dump(start), source="start"), lc, free=free)
        seconds = time.perf_counter() - t0
        p = pulls(result, truth)
        key = "roughness" if "roughness" in free else "albedo"
        for name, values in p.items():  # pulls of every value with a sigma
            found[name] += [float(v) for v in values if np.isfinite(v)]
        finite = p[key][np.isfinite(p[key])]
        recovered += int(finite.size > 0 and np.all(np.abs(finite) < 3))
        if not result.converged:
            said.append(result.message)
        if key == "albedo":
            true_text, est_text = f"{truth[key]:.3f}", f"{result.albedo[0]:.3f}"
        else:
            rough = truth[key] if isinstance(truth[key], dict) else {"*": truth[key]}
            true_text = " ".join(f"{rough[name]:.3f}" for name in result.roughness)
            est_text = " ".join(f"{v:.3f}" for v, _ in result.roughness.values())
        print(
            f"| {k} | {true_text} | {truth.get('start', 0.4):.3f} | {est_text} | "
            f"{float(np.max(np.abs(finite), initial=0)):.2f} | {result.converged} | "
            f"{seconds:.1f} | {'' if result.converged else result.message[:120]} |",
            flush=True,
        )
    print(f"\nrecovered (every {kind} with a sigma within 3 of it): {recovered}/{n}")
    for name, values in found.items():
        if values:
            v = np.array(values)
            print(
                f"{name} pulls (every value with a sigma): n {v.size}, mean {v.mean():+.3f}, std "
                f"{v.std(ddof=1):.3f}, median |pull| {np.median(np.abs(v)):.3f} (calibrated: "
                "0, 1, 0.674)"
            )
    for text in said:
        print(f"not converged: {text[:300]}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--draws", type=int, default=50)
    parser.add_argument("--kind", choices=("albedo", "roughness", "faces", "both"), default="both")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    if args.kind in ("albedo", "both"):
        run("albedo", albedo_draw, args.draws, rng)
    if args.kind in ("roughness", "both"):
        run("roughness", roughness_draw, args.draws, rng)
    if args.kind == "faces":
        run("roughness", faces_draw, args.draws, rng)


if __name__ == "__main__":
    main()
