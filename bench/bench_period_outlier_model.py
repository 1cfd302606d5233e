"""Does the outlier test need the refinement's chosen model? (issue 25, BENCHMARKS.md).

Light curves of 2 or 5 harmonics (23.7 s, 400 epochs at 1 s, 3 bands, a quadratic trend
with a bump and a 10 % amplitude change over the pass), one cosmic ray of ``R`` sigma at
one epoch of one band; :func:`speclight.estimate.period.outliers.find_outliers` about the
periodogram's harmonics and a cubic ("fixed") and about the model
:func:`.peak_refinement.refine_with_model` chooses ("chosen"). Printed: how often the ray is
found and how many other points are left out, over the noise draws.

Usage: ``python bench/bench_period_outlier_model.py [--draws 15] [--seed 5]``.
"""

from __future__ import annotations

import argparse

import numpy as np

from speclight.estimate.period.outliers import find_outliers
from speclight.estimate.period.peak_refinement import refine_with_model
from speclight.estimate.period.periodogram import BandSeries

PERIOD_S = 23.7
N = 400
RAY_AT = N + 200  # the ray's index in the series: band 1, epoch 200


def _draw(rng: np.random.Generator, ray_sigma: float, amplitudes: tuple[float, ...]) -> BandSeries:
    t = np.arange(float(N))
    u = 2 * t / t[-1] - 1
    x = 2 * np.pi * t / PERIOD_S
    curve = sum(a * np.cos(k * x + k) for k, a in enumerate(amplitudes, 1))
    ts, ys, dys, bs = [], [], [], []
    for b, sigma in enumerate((0.01, 0.015, 0.02)):
        trend = 0.3 * u**2 + 0.05 * np.exp(-(((t - 150) / 40) ** 2))
        y = trend + (1 + 0.1 * u) * curve + rng.normal(0, sigma, t.size)
        if b == 1:
            y[200] += ray_sigma * sigma
        ts.append(t)
        ys.append(y)
        dys.append(np.full(t.size, sigma))
        bs.append(np.full(t.size, b, dtype=np.int64))
    return BandSeries(np.concatenate(ts), np.concatenate(ys), np.concatenate(dys),
                      np.concatenate(bs), 3)  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--draws", type=int, default=15)
    parser.add_argument("--seed", type=int, default=5)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    for amplitudes in ((0.3, 0.1), (0.3, 0.2, 0.15, 0.1, 0.05)):
        for ray in (0.0, 6.0, 8.0, 12.0):
            found = {"fixed": [0, 0], "chosen": [0, 0]}
            for _ in range(args.draws):
                series = _draw(rng, ray, amplitudes)
                pk = refine_with_model(series, 1 / PERIOD_S, 2)
                model = (pk.orders, pk.trend_degree, pk.amplitude_change)
                for name, o in (
                    ("fixed", find_outliers(series, pk.frequency_hz, [1, 2])),
                    ("chosen", find_outliers(series, pk.frequency_hz, *model)),
                ):
                    hit = bool(np.any(o.index == RAY_AT))
                    found[name][0] += hit
                    found[name][1] += o.index.size - hit
            text = ", ".join(
                f"{k}: ray found {v[0]}/{args.draws}, others {v[1]}" for k, v in found.items()
            )
            print(f"{len(amplitudes)} harmonics, ray {ray:g} sigma: {text}")


if __name__ == "__main__":
    main()
