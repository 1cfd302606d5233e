"""The terms of ``period_std_s`` against the scatter over noise draws (issue 25).

For a few fixed truths (draws of :mod:`bench_calibration_period` with their trend and
amplitude change, and the same truths without them), ``--noise`` noise realisations each go
through ``estimate_period``. Per truth: the empirical standard deviation of the period over
the realisations against the median of each term of the reported sigma: the white-noise
least-squares sigma with the sigmas as given (``white``), the noise factor on it
(``factor``: the residuals' noise level near the harmonics over the sigmas' level),
the reduced chi-square, and the reported ``period_std_s``. The ratio
``std(P) / median(period_std_s)`` should be near 1.

Run: ``.venv/bin/python bench/bench_period_sigma_terms.py [--truths 4] [--noise 40]
[--all-variants]``
"""

from __future__ import annotations

import argparse
import tempfile
import warnings
from pathlib import Path

import numpy as np

from bench_calibration_period import draw, light_curve
from speclight.estimate.period.period_run import estimate_period

#: The variants of each truth: as drawn, without the trend, without the amplitude change,
#: without both.
VARIANTS = ("as drawn", "no trend", "no change", "no trend, no change")


def truths(count: int, seed: int) -> list[tuple[dict, int]]:
    """The first ``count`` rotation draws of the calibration bench's generator, with the
    seed of the generator that draws their trend and light curve."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(200):
        case = draw(rng)
        if not case["null"] and case["span"] / case["period"] >= 5:
            out.append((case, 1000 * seed + i))
        if len(out) == count:
            break
    return out


def run(case: dict, shape_seed: int, noise: int, tmp: Path) -> dict[str, float]:
    periods, reported, white, factor, chi2 = [], [], [], [], []
    for j in range(noise):
        path = tmp / f"n{j}.csv"
        light_curve(case, np.random.default_rng(shape_seed), path, np.random.default_rng(j))
        r = estimate_period(path, if_symmetric="keep")
        if not r.detected or abs(r.period_s / case["period"] - 1) > 0.02:
            continue
        f = r.peak.frequency_hz
        scale = r.decision.factor / f**2
        periods.append(r.period_s)
        reported.append(r.period_std_s)
        white.append(r.peak.white_std_hz * scale)
        factor.append(r.peak.noise_factor)
        chi2.append(r.peak.chi2 / r.peak.dof)
    p = np.asarray(periods)
    return {
        "n": p.size, "bias": (p.mean() - case["period"]) / np.std(p, ddof=1),
        "std_p": np.std(p, ddof=1), "reported": np.median(reported),
        "white": np.median(white), "factor": np.median(factor), "chi2": np.median(chi2),
    }  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--truths", type=int, default=4)
    parser.add_argument("--noise", type=int, default=40)
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--all-variants", action="store_true", help="also trend or change alone")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    print("case                                   n  std(P)/rep  std(P)/white  factor  chi2_red  "
          "bias/std")  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        for case, shape_seed in truths(args.truths, args.seed):
            for variant in VARIANTS if args.all_variants else VARIANTS[::3]:
                c = dict(case)
                if "no trend" in variant:
                    c["trend"] = 0.0
                if "no change" in variant:
                    c["change"] = 0.0
                s = run(c, shape_seed, args.noise, Path(tmp))
                label = (f"P {c['period']:6.2f} span {c['span']:4.0f} K {c['harmonics']} "
                         f"SNR {c['snr']:3.0f} {variant[:9]}")  # fmt: skip
                print(f"{label:38s} {s['n']:2d}  {s['std_p'] / s['reported']:9.2f}  "
                      f"{s['std_p'] / s['white']:11.2f}  {s['factor']:6.2f}  {s['chi2']:8.2f}  "
                      f"{s['bias']:+7.2f}", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
