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
  Its fits take minutes: ``bench_calibration_faces.py`` checks the same draws at the truth
  without fits (marginal and conditional Fisher sigmas, linearised pulls, noise redraws).

It prints, per kind, the fraction recovered (converged, and within 3 reported sigmas of the
truth), the standard deviation and the median absolute value of the pulls ``(estimate -
truth) / sigma`` (a calibrated sigma gives 1 and 0.67) with the 95 % range of the standard
deviation of that many normal pulls, and what the fit said where it did not converge.

For the roughness kinds every draw is also checked at the **truth**, without the fit
(:func:`truth_check`): the deviance per measurement at the true model (is the noise model
the simulation's?), the Fisher sigma there (is the reported sigma the Cramer-Rao one?), and
with one roughness the linearised maximum-likelihood pull of the same measurements (does the
fit reach the maximum?) and its standard deviation over :data:`GENERATOR_DRAWS` new draws of
the simulation's noise generator (is the sigma calibrated at this geometry, from many more
draws than the bench's one per geometry?). A standard deviation over 50 blind pulls
scatters by about 0.1: these checks say whether a value at the edge of 0.8-1.25 is the
sigma's or the draws' (BENCHMARKS.md, "Fit calibration").
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from scipy.stats import chi2

from speclight.estimate import FitResult, MeasuredLightCurve, fit_scenario
from speclight.estimate.fitting.fit import joint_std
from speclight.estimate.fitting.fit_inputs import noise_of
from speclight.estimate.fitting.noise_model import Likelihood
from speclight.instrument import simulate_measurement
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate

CUBE = Path(__file__).parent.parent / "tests" / "estimate" / "data" / "spinning_cube.yaml"


def _rates(d: dict[str, Any]) -> Any:
    """The simulation of the scenario ``d`` (a dict of its YAML)."""
    return simulate(parse_scenario(yaml.safe_dump(d), source="truth")).dataset


def measured_of(d: dict[str, Any]) -> MeasuredLightCurve:
    ds = _rates(d)
    rate = ds["count_rate_measured"].transpose("time", "band").values
    bands = [str(b) for b in ds["band"].values]
    n = ds.sizes["time"]
    return MeasuredLightCurve(ds["time"].values, bands, rate, None, np.ones(n, np.int64), "sim")


#: Half step of the central differences of the truth check, relative to the roughness [1].
TRUTH_STEP = 1e-5
#: Noise draws of the truth check's linearised estimates, per geometry.
GENERATOR_DRAWS = 200


@dataclass
class TruthCheck:
    """What the fit should find and claim, computed at the **truth** without the fit.

    Attributes
    ----------
    deviance_per_n
        The measurements' deviance at the true model per measurement: about 1 when the
        fit's noise model is the simulation's (``1 +- sqrt(2 / n)``).
    fisher_std
        Every roughness's Fisher standard deviation ``sqrt((J^T W J)^-1)`` at the truth (J by
        central differences of half step :data:`TRUTH_STEP` x the roughness, the band scales
        fitted jointly, W the Poisson weights): the Cramer-Rao bound that the fit's sigma
        should equal.
    linear_pull
        With one roughness: the error of the linearised maximum-likelihood estimate
        ``(J^T W J)^-1 J^T W (m - c)`` made from the same measurements ``m``, over the Fisher
        std (the fit's own pull should equal it where the fit finds the maximum), else NaN.
    generator_std
        With one roughness: the standard deviation of that linearised pull over
        :data:`GENERATOR_DRAWS` new noise draws of the simulation's own generator
        (:func:`speclight.instrument.simulate_measurement`, this scenario's sky, dark current
        and read noise): whether the sigma is calibrated at this geometry, from many more
        draws than one fit per geometry gives; else NaN.
    """

    deviance_per_n: float
    fisher_std: dict[str, float]
    linear_pull: float
    generator_std: float


def truth_check(d: dict[str, Any], lc: MeasuredLightCurve) -> TruthCheck:
    """:class:`TruthCheck` of the scenario ``d`` (the truth) and its measurements ``lc``."""
    truth = parse_scenario(yaml.safe_dump(d), source="truth")
    ds = _rates(d)
    c = ds["count_rate"].transpose("time", "band").values
    noise = noise_of(truth, lc, ds)
    likelihood = Likelihood(lc.rate_per_s, noise)
    cols, names = [], []
    for name, material in d["target"]["materials"].items():
        alpha = material.get("roughness")
        if not alpha:
            continue
        h = TRUTH_STEP * alpha
        side = []
        for a in (alpha - h, alpha + h):
            other = yaml.safe_load(yaml.safe_dump(d))
            other["target"]["materials"][name]["roughness"] = a
            side.append(_rates(other)["count_rate"].transpose("time", "band").values)
        cols.append((side[1] - side[0]) / (2 * h))
        names.append(name)
    std, _ = joint_std(cols, c, likelihood, np.ones(c.shape[1]), True)
    deviance = float(np.sum(likelihood.deviance(c))) / int(np.count_nonzero(likelihood.mask(c)))
    fisher = dict(zip(names, (float(x) for x in std), strict=True))
    if len(cols) != 1:
        return TruthCheck(deviance, fisher, np.nan, np.nan)
    # the linearised estimate: J = [dc/dalpha, c of band j in column j], W Poisson weights
    n_b = c.shape[1]
    w = likelihood.weights(c).ravel()
    band_cols = [np.where(np.arange(n_b)[None, :] == j, c, 0.0).ravel() for j in range(n_b)]
    jac = np.stack([cols[0].ravel(), *band_cols], axis=1)
    cov = np.linalg.inv(jac.T @ (w[:, None] * jac))
    sigma = float(np.sqrt(cov[0, 0]))

    def pull(m: np.ndarray) -> float:
        error = np.where(likelihood.used, m - c, 0.0).ravel()
        return float((cov @ (jac.T @ (w * error)))[0]) / sigma

    exposure = float(d["instrument"]["exposure_s"])
    read_e = float(d["instrument"]["noise"].get("read_noise_e", 0.0))
    background = (noise.background_e[0] - read_e**2) / exposure  # sky + dark [s-1] (B,)
    draws = [
        pull(simulate_measurement(c, exposure, sky_count_rate_per_s=background,
                                  read_noise_e=read_e, seed=k))
        for k in range(GENERATOR_DRAWS)
    ]  # fmt: skip
    return TruthCheck(deviance, fisher, pull(lc.rate_per_s), float(np.std(draws, ddof=1)))


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
    print(
        "| draw | truth | start | estimate | pull | converged | s | sigma / Fisher sigma at "
        "truth | deviance / n at truth | linearised pull | its std over "
        f"{GENERATOR_DRAWS} noise draws | said |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    found: dict[str, list[float]] = {"albedo": [], "roughness": []}
    recovered, said = 0, []
    checks: list[TruthCheck] = []
    ratios, gaps = [], []  # sigma / Fisher sigma; fit pull - linearised pull
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
        check_text = "- | - | - | -"
        if key == "roughness":
            check = truth_check(d, lc)
            checks.append(check)
            r = [s / check.fisher_std[name] for name, (_, s) in result.roughness.items()
                 if np.isfinite(s) and np.isfinite(check.fisher_std.get(name, np.nan))]  # fmt: skip
            ratios += r
            if np.isfinite(check.linear_pull) and finite.size == 1:
                gaps.append(float(finite[0]) - check.linear_pull)
            check_text = (
                f"{' '.join(f'{x:.3f}' for x in r) or '-'} | {check.deviance_per_n:.3f} | "
                f"{check.linear_pull:+.2f} | {check.generator_std:.3f}"
            )
        if key == "albedo":
            true_text, est_text = f"{truth[key]:.3f}", f"{result.albedo[0]:.3f}"
        else:
            rough = truth[key] if isinstance(truth[key], dict) else {"*": truth[key]}
            true_text = " ".join(f"{rough[name]:.3f}" for name in result.roughness)
            est_text = " ".join(f"{v:.3f}" for v, _ in result.roughness.values())
        signed = f"{float(finite[0]):+.2f}" if finite.size == 1 else (
            f"max {float(np.max(np.abs(finite), initial=0)):.2f}")  # fmt: skip
        print(
            f"| {k} | {true_text} | {truth.get('start', 0.4):.3f} | {est_text} | {signed} | "
            f"{result.converged} | {seconds:.1f} | {check_text} | "
            f"{'' if result.converged else result.message[:120]} |",
            flush=True,
        )
    print(f"\nrecovered (every {kind} with a sigma within 3 of it): {recovered}/{n}")
    for name, values in found.items():
        if values:
            v = np.array(values)
            low, high = np.sqrt(chi2.ppf([0.025, 0.975], v.size - 1) / (v.size - 1))
            print(
                f"{name} pulls (every value with a sigma): n {v.size}, mean {v.mean():+.3f}, std "
                f"{v.std(ddof=1):.3f} (95 % of the standard deviations of {v.size} normal "
                f"pulls lie in {low:.2f}-{high:.2f}), median |pull| {np.median(np.abs(v)):.3f} "
                "(calibrated: 0, 1, 0.674)"
            )
    if checks:
        q = np.percentile(ratios, [0, 50, 100]) if ratios else np.full(3, np.nan)
        dev = np.array([c.deviance_per_n for c in checks])
        print(
            f"truth check: sigma / Fisher sigma at the truth min {q[0]:.3f}, median {q[1]:.3f}, "
            f"max {q[2]:.3f}; deviance / n at the truth mean {dev.mean():.3f}, std "
            f"{dev.std(ddof=1) if dev.size > 1 else 0.0:.3f} (noise model right: 1, sqrt(2 / n))"
        )
        lin = np.array([c.linear_pull for c in checks if np.isfinite(c.linear_pull)])
        gen = np.array([c.generator_std for c in checks if np.isfinite(c.generator_std)])
        if lin.size > 1 and gaps:
            print(
                f"linearised maximum-likelihood pulls of the same measurements: std "
                f"{lin.std(ddof=1):.3f}; fit pull - linearised pull: rms "
                f"{np.sqrt(np.mean(np.square(gaps))):.3f} (the fit finds the maximum); over "
                f"{GENERATOR_DRAWS} new noise draws per geometry ({gen.size * GENERATOR_DRAWS} in "
                f"all): std per geometry {gen.min():.3f}-{gen.max():.3f}, pooled "
                f"{np.sqrt(np.mean(gen**2)):.3f}"
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
