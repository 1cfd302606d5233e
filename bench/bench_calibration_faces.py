"""Are the per-face cube's roughness sigmas the Cramer-Rao ones? Checks at the truth (issue 25).

Run: ``PYTHONPATH=src .venv/bin/python bench/bench_calibration_faces.py [--draws 50]
[--seed 2] [--fits 0]``

The cube with a material per face (``--kind faces`` of :mod:`bench_calibration_fit`) takes
minutes per fit, so its calibration is checked at the **truth**, without fits: for every
draw of truth and geometry (:func:`bench_calibration_fit.faces_draw`), the Jacobian of the
simulated rates in the six roughness values (central differences of half step
:data:`bench_calibration_fit.TRUTH_STEP` x the value) and in the two band scales gives

* the Fisher standard deviation of every side face (``+x``, ``-x``, ``+y``, ``-y``) **marginal**
  over the other faces and the scales with ``+z`` and ``-z`` (the spin axis's faces, which
  never glint) free too, the joint ``(J^T W J)^-1`` that ``fit`` computes
  (:func:`speclight.estimate.fitting.fit.joint_std`), and **with** ``+z`` **and** ``-z``
  **held** (marginal over the side faces and scales only);
* the linearised maximum-likelihood estimate ``(J^T W J)^-1 J^T W (m - c)`` of the side
  faces with ``+z`` and ``-z`` held at the truth, from the draw's measurements and from
  :data:`bench_calibration_fit.GENERATOR_DRAWS` new draws of the simulation's own noise
  generator (seeded after the draw's own seed, so that no two draws share noise), divided
  by either sigma;
* the deviance per measurement at the truth.

``--fits N`` also fits the first N draws from their far start (default method) and prints
the reported sigmas, the pulls and the fit's error minus the linearised one of the same
noise (the fit reaching the maximum-likelihood estimate).
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import yaml

from bench_calibration_fit import (
    FACES,
    GENERATOR_DRAWS,
    TRUTH_STEP,
    _rates,
    faces_draw,
    measured_of,
)
from speclight.estimate import MeasuredLightCurve, fit_scenario
from speclight.estimate.fitting.fit import joint_std
from speclight.estimate.fitting.fit_inputs import noise_of
from speclight.estimate.fitting.noise_model import Likelihood
from speclight.instrument import simulate_measurement
from speclight.scenario import parse_scenario

SIDES = FACES[:4]


def _rate(d: dict) -> np.ndarray:
    return _rates(d)["count_rate"].transpose("time", "band").values


def check(d: dict, lc: MeasuredLightCurve) -> dict[str, np.ndarray | float]:
    """The module doc's numbers for the draw ``d`` (the truth) and its measurements ``lc``."""
    truth = parse_scenario(yaml.safe_dump(d), source="truth")
    ds = _rates(d)
    c = ds["count_rate"].transpose("time", "band").values
    noise = noise_of(truth, lc, ds)
    likelihood = Likelihood(lc.rate_per_s, noise)
    cols = []
    for face in FACES:
        alpha = d["target"]["materials"][face]["roughness"]
        side = []
        for a in (alpha * (1 - TRUTH_STEP), alpha * (1 + TRUTH_STEP)):
            other = yaml.safe_load(yaml.safe_dump(d))
            other["target"]["materials"][face]["roughness"] = a
            side.append(_rate(other))
        cols.append((side[1] - side[0]) / (2 * TRUTH_STEP * alpha))
    ones = np.ones(c.shape[1])
    marginal, _ = joint_std(cols, c, likelihood, ones, True)
    held, held_scale = joint_std(cols[:4], c, likelihood, ones, True)
    # conditional: every other roughness and the scales held at the truth
    alone = np.array([joint_std([x], c, likelihood, ones, False)[0][0] for x in cols[:4]])
    # linearised estimate of the side faces, +z and -z held at the truth
    n_b = c.shape[1]
    w = likelihood.weights(c).ravel()
    band_cols = [np.where(np.arange(n_b)[None, :] == j, c, 0.0).ravel() for j in range(n_b)]
    jac = np.stack([x.ravel() for x in cols[:4]] + band_cols, axis=1)
    cov = np.linalg.inv(jac.T @ (w[:, None] * jac))

    def estimate(m: np.ndarray) -> np.ndarray:
        error = np.where(likelihood.used, m - c, 0.0).ravel()
        return cov @ (jac.T @ (w * error))  # +x, -x, +y, -y, then the band scales

    exposure = float(d["instrument"]["exposure_s"])
    read_e = float(d["instrument"]["noise"].get("read_noise_e", 0.0))
    background = (noise.background_e[0] - read_e**2) / exposure
    first = int(d["instrument"]["noise"]["seed"]) + 1  # redraws differ between draws
    redraws = np.array([
        estimate(simulate_measurement(c, exposure, sky_count_rate_per_s=background,
                                      read_noise_e=read_e, seed=first + k))
        for k in range(GENERATOR_DRAWS)
    ])  # fmt: skip
    n_used = int(np.count_nonzero(likelihood.mask(c)))
    return {
        "marginal": marginal[:4],
        "marginal_z": marginal[4:],
        "held": held,
        "held_scale": held_scale,
        "fisher": np.sqrt(np.diag(cov)),
        "alone": alone,
        "linear": estimate(lc.rate_per_s),
        "redraws": redraws,
        "deviance": float(np.sum(likelihood.deviance(c))) / n_used,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--draws", type=int, default=50)
    parser.add_argument("--seed", type=int, default=2)
    parser.add_argument("--fits", type=int, default=0)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    print("| draw | truth +x -x +y -y (+z -z) | held / marginal sigma | marginal sigma +z -z |"
          " linearised pulls (held sigma) | conditional / held sigma | linearised pulls of the"
          " band scales | deviance / n |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    rows = []
    for k in range(args.draws):
        d, start, free, truth = faces_draw(rng)
        lc = measured_of(d)
        r = check(d, lc)
        rows.append(r)
        a = truth["roughness"]
        print(
            f"| {k} | {' '.join(f'{a[f]:.3f}' for f in SIDES)} ({a['+z']:.3f} {a['-z']:.3f}) | "
            f"{' '.join(f'{x:.3f}' for x in r['held'] / r['marginal'])} | "
            f"{' '.join(f'{x:.3g}' for x in r['marginal_z'])} | "
            f"{' '.join(f'{x:+.2f}' for x in r['linear'][:4] / r['held'])} | "
            f"{' '.join(f'{x:.3f}' for x in r['alone'] / r['held'])} | "
            f"{' '.join(f'{x:+.2f}' for x in r['linear'][4:] / r['held_scale'])} | "
            f"{r['deviance']:.3f} |",
            flush=True,
        )
        if k < args.fits:
            t0 = time.perf_counter()
            result = fit_scenario(parse_scenario(yaml.safe_dump(start), source="s"), lc, free=free)
            seconds = time.perf_counter() - t0
            value = np.array([result.roughness[f][0] for f in SIDES])
            sigma = np.array([result.roughness[f][1] for f in SIDES])
            error = value - np.array([a[f] for f in SIDES])
            albedo_pull = (result.albedo - truth["albedo"]) / result.albedo_std
            print(
                f"  fit {seconds:.0f} s, converged {result.converged}: sigma / held "
                f"{' '.join(f'{x:.3f}' for x in sigma / r['held'])}, sigma / marginal "
                f"{' '.join(f'{x:.3f}' for x in sigma / r['marginal'])}, pulls "
                f"{' '.join(f'{x:+.2f}' for x in error / sigma)}, (fit - linearised) / held "
                f"sigma {' '.join(f'{x:+.3f}' for x in (error - r['linear'][:4]) / r['held'])}; "
                f"+z, -z {result.roughness['+z'][0]:.3f}, {result.roughness['-z'][0]:.3f}; "
                f"albedo pulls {' '.join(f'{x:+.2f}' for x in albedo_pull)} "
                f"(linearised {' '.join(f'{x:+.2f}' for x in r['linear'][4:] / r['held_scale'])})"
                f"; said: {result.message[:160]}",
                flush=True,
            )
    held = np.array([r["held"] for r in rows])
    marginal = np.array([r["marginal"] for r in rows])
    linear = np.array([r["linear"][:4] for r in rows])
    redraws = np.concatenate([r["redraws"][:, :4] / r["held"] for r in rows])
    dev = np.array([r["deviance"] for r in rows])
    ratio = (held / marginal).ravel()
    alone = np.array([r["alone"] / r["held"] for r in rows]).ravel()
    scale = np.array([r["linear"][4:] / r["held_scale"] for r in rows]).ravel()
    scale_draws = np.concatenate([r["redraws"][:, 4:] / r["held_scale"] for r in rows]).ravel()
    print(
        f"\nconditional / held sigma (what ignoring the correlations would claim): min "
        f"{alone.min():.3f}, median {np.median(alone):.3f}, max {alone.max():.3f}"
    )
    print(
        f"band scale (albedo) linearised pulls: same noise n {scale.size}, mean "
        f"{scale.mean():+.3f}, std {scale.std(ddof=1):.3f}; {scale_draws.size} generator "
        f"draws std {scale_draws.std(ddof=1):.3f}"
    )
    fisher = np.concatenate([r["redraws"] / r["fisher"] for r in rows])
    print(
        f"over the Fisher sigma without fit's max(1, chi2/dof) factor, {fisher.shape[0]} "
        f"generator draws: side faces std {fisher[:, :4].std(ddof=1):.3f}, band scales "
        f"{fisher[:, 4:].std(ddof=1):.3f}"
    )
    print(f"\nheld / marginal sigma: min {ratio.min():.3f}, median {np.median(ratio):.3f}, "
          f"max {ratio.max():.3f}")  # fmt: skip
    for name, sig in (("held", held), ("marginal", marginal)):
        p = (linear / sig).ravel()
        g = (np.concatenate([r["redraws"][:, :4] for r in rows]) /
             np.repeat(sig, GENERATOR_DRAWS, axis=0)).ravel()  # fmt: skip
        print(
            f"linearised pulls / {name} sigma: same noise n {p.size}, mean {p.mean():+.3f}, "
            f"std {p.std(ddof=1):.3f}; {g.size} generator draws std {g.std(ddof=1):.3f}"
        )
    per = redraws.std(axis=0, ddof=1)
    print(
        f"generator std per face (held sigma): {' '.join(f'{x:.3f}' for x in per)}; "
        f"deviance / n at the truth {dev.mean():.3f} +- {dev.std(ddof=1):.3f}"
    )


if __name__ == "__main__":
    main()
