"""Calibration of ``speclight period`` over blind draws (issue 25; BENCHMARKS.md,
"Period: calibration over blind draws").

Each draw picks, from a seeded generator the estimator never sees: a pass of 300-900 s at
a cadence of 0.5-2 s in 1-3 bands; an SNR of 15-200; a smooth trend over the pass (a
polynomial plus a bump no cubic removes, 0-1 mag, as range, phase angle and the Earth's
penumbra make); and either a rotation (a period log-uniform from 4 cadences to a fifth of
the pass, 1-4 harmonics of random amplitudes 0.05-0.5 mag and phases, a slow change of the
amplitude over the pass of up to 20 %) or none (a null case, one draw in four). The CSV goes
through ``estimate_period`` with its defaults (``if_symmetric="keep"``: the light curves
drawn are not symmetric).

Reported: the fraction of rotations detected and recovered (the period within 2 % of the
truth), the standard deviation of ``(estimate - truth) / sigma`` over the recovered ones, its
median absolute value and the fractions beyond 2 and 3 sigma (the tails), and what is said
on the null draws (false detections: a period at FAP < 0.01). Per draw: the pull, the noise
factor on the white-noise sigma (``Peak.noise_factor``) and the refinement's model.

Run: ``.venv/bin/python bench/bench_calibration_period.py [--draws 60] [--seed 2026]``
"""

from __future__ import annotations

import argparse
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

from speclight.estimate.period.period_run import estimate_period


def draw(rng: np.random.Generator) -> dict:
    span = rng.uniform(300, 900)
    dt = rng.uniform(0.5, 2.0)
    case = {
        "span": span, "dt": dt, "bands": int(rng.integers(1, 4)), "snr": rng.uniform(15, 200),
        "trend": rng.uniform(0, 1), "null": bool(rng.random() < 0.25),
        "period": float(np.exp(rng.uniform(np.log(4 * dt), np.log(span / 5)))),
        "harmonics": int(rng.integers(1, 5)), "change": rng.uniform(0, 0.2),
    }  # fmt: skip
    return case


def light_curve(
    case: dict, rng: np.random.Generator, path: Path, noise: np.random.Generator | None = None
) -> None:
    """Write the CSV of ``case``: its trend, light curve and band factors from ``rng``,
    the noise from ``noise`` (default ``rng``, drawn last)."""
    t = np.arange(0.0, case["span"], case["dt"])
    x = t / t[-1]
    c = rng.normal(0, 1, 3)
    bump = rng.uniform(0.05, 0.3)
    trend = case["trend"] * (
        c[0] * x + c[1] * x**2 + c[2] * x**3 + np.exp(-(((x - rng.uniform(0.1, 0.9)) / bump) ** 2))
    )
    signal = np.zeros_like(t)
    if not case["null"]:
        ph = 2 * np.pi * t / case["period"]
        grow = 1 + case["change"] * (x - 0.5)
        for k in range(1, case["harmonics"] + 1):
            signal += rng.uniform(0.05, 0.5) / k * grow * np.cos(k * ph + rng.uniform(0, 2 * np.pi))
    nb = case["bands"]
    mag = (trend + signal)[:, None] * rng.uniform(0.8, 1.2, nb) + rng.uniform(0, 0.5, nb)
    rate = 1e4 * 10 ** (-0.4 * mag)
    sigma = rate / case["snr"]
    rate = rate + (rng if noise is None else noise).normal(0, sigma)
    names = ["B", "G", "R"][:nb]
    start = np.datetime64("2021-03-01T20:00:00", "ms")
    lines = ["time," + ",".join(names) + "," + ",".join(f"{n}_sigma" for n in names)]
    for i, ti in enumerate(t):
        stamp = f"{start + np.timedelta64(round(ti * 1000), 'ms')}Z"
        lines.append(
            ",".join([stamp, *(f"{v:.7g}" for v in rate[i]), *(f"{v:.7g}" for v in sigma[i])])
        )
    path.write_text("\n".join(lines) + "\n")


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--draws", type=int, default=60)
    parser.add_argument("--seed", type=int, default=2026)
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    rng = np.random.default_rng(args.seed)
    pulls, rotations, recovered, nulls, false_det, bounds, seconds = [], 0, 0, 0, 0, 0, []
    edges = 0
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(args.draws):
            case = draw(rng)
            path = Path(tmp) / f"d{i}.csv"
            light_curve(case, rng, path)
            t0 = time.perf_counter()
            result = estimate_period(path, if_symmetric="keep")
            out = result.to_json()
            seconds.append(time.perf_counter() - t0)
            truth = case["period"]
            if case["null"]:
                nulls += 1
                false_det += bool(out["detected"])
                bounds += out["period_lower_bound_s"] is not None
                what = f"null: detected={out['detected']} fap={out['false_alarm_probability']:.2g}"
            else:
                rotations += 1
                p, s = out["period_s"], out["period_std_s"]
                ok = p is not None and abs(p / truth - 1) < 0.02
                recovered += ok
                edge = out["search_edge"] is not None  # said, and no sigma (docs/period.md)
                edges += edge
                if ok and not edge:
                    pulls.append((p - truth) / s)
                pull = "EDGE" if edge else f"pull {(p - truth) / s:+6.2f}" if ok else "MISS"
                what = (f"P {truth:8.3f} -> {p if p is None else round(p, 4)} +- "
                        f"{s if s is None else round(s, 4)} {pull} (factor "
                        f"{result.peak.noise_factor:.2f}, harmonics {len(result.peak.orders)}, "
                        f"trend degree {result.peak.trend_degree})")  # fmt: skip
            print(f"{i:3d} span {case['span']:5.0f} dt {case['dt']:.2f} B {case['bands']} "
                  f"SNR {case['snr']:5.0f} trend {case['trend']:.2f} K {case['harmonics']} {what}",
                  flush=True)  # fmt: skip
    pulls_a = np.asarray(pulls)
    print(f"\nrotations: {recovered}/{rotations} recovered ({recovered / max(rotations, 1):.0%}); "
          f"{edges} at an edge of the searched range (no sigma)")  # fmt: skip
    if pulls_a.size > 1:
        beyond2, beyond3 = (float(np.mean(np.abs(pulls_a) > k)) for k in (2, 3))
        print(f"(estimate - truth)/sigma over the recovered: mean {pulls_a.mean():+.2f}, "
              f"std {pulls_a.std(ddof=1):.2f}, median |pull| {np.median(np.abs(pulls_a)):.2f} "
              f"(0.67 for a unit normal), beyond 2 sigma {beyond2:.1%} (4.6 %), beyond 3 "
              f"sigma {beyond3:.1%} (0.27 %) (n = {pulls_a.size})")  # fmt: skip
    print(f"null draws: {false_det}/{nulls} false detections, {bounds} with a lower bound")
    print(f"seconds per draw: median {np.median(seconds):.2f}, max {np.max(seconds):.2f}")


if __name__ == "__main__":
    main()
