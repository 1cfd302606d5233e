"""Does the synodic fit need the refinement's chosen model? (issue 25, BENCHMARKS.md).

A light curve that follows the phase-angle bisector exactly (rotation phase
``2 pi f_sid t - phi(t)``, ``phi`` the bisector's azimuth about the spin axis turning fastest
near mid-pass) with 4 harmonics, a slow trend with a bump no cubic removes and an amplitude
that changes over the pass, in 2 bands, noise drawn many times. The sidereal period of
:func:`speclight.estimate.period.synodic.sidereal_period` is fitted with its fixed model
(harmonics ``1..2K`` of the rotation frequency and a cubic) and with the model the
refinement chooses in the bisector's frame (``choose_model``); printed per model: the scatter of the
estimates over the median ``sidereal_std_s`` (1 when the sigma is right), the bias over the
scatter, and the pulls' standard deviation.

Usage: ``python bench/bench_period_synodic_model.py [--draws 30] [--seed 0]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from speclight.estimate.period.peak_refinement import refine_with_model
from speclight.estimate.period.periodogram import BandSeries
from speclight.estimate.period.synodic import sidereal_period

P_SID = 37.0
SPAN = 600
K = 2


def _draw(
    rng: np.random.Generator, bump_mag: float = 0.1
) -> tuple[BandSeries, np.ndarray, np.ndarray, np.ndarray]:
    t = np.arange(float(SPAN))
    phi = 1.2 * np.arctan((t - SPAN / 2) / 60.0)  # the bisector's azimuth about the axis
    pab = np.stack([np.cos(phi), np.sin(phi), np.full_like(t, 0.3)], axis=1)
    x = 2 * np.pi * t / P_SID - phi
    u = 2 * t / t[-1] - 1
    curve = sum(
        a * np.cos(k * x + c)
        for k, a, c in ((1, 0.3, 0), (2, 0.15, 1), (3, 0.08, 2), (4, 0.04, 0.5))
    )
    trend = 0.4 * u**2 + bump_mag * np.exp(-(((t - 200) / 50) ** 2))
    ts, ys, dys, bs = [], [], [], []
    for b, sigma in enumerate((0.01, 0.02)):
        ts.append(t)
        ys.append(trend + (1 + 0.15 * u) * curve * (1 + 0.1 * b) + rng.normal(0, sigma, t.size))
        dys.append(np.full(t.size, sigma))
        bs.append(np.full(t.size, b, dtype=np.int64))
    series = BandSeries(np.concatenate(ts), np.concatenate(ys), np.concatenate(dys),
                        np.concatenate(bs), 2)  # fmt: skip
    return series, t, pab, np.ones(t.size)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--draws", type=int, default=30)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--bump-mag", type=float, default=0.1, help="the trend's bump [mag]")
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    axis = np.array([0.0, 0.0, 1.0])
    rows: dict[str, list[tuple[float, float]]] = {"fixed": [], "chosen": []}
    start = time.perf_counter()
    for _ in range(args.draws):
        series, t, pab, weight = _draw(rng, args.bump_mag)
        rate = np.gradient(1.2 * np.arctan((t - SPAN / 2) / 60.0), t).mean()
        f_syn = 1 / P_SID - rate / (2 * np.pi)
        peak = refine_with_model(series, f_syn, K)
        p_syn = 1 / peak.frequency_hz
        for name, choose in (("fixed", False), ("chosen", True)):
            c = sidereal_period(series, p_syn, K, t, pab, weight, axis, choose_model=choose)
            if c.sidereal_period_s is not None and c.sidereal_std_s is not None:
                rows[name].append((c.sidereal_period_s, c.sidereal_std_s))
    took = time.perf_counter() - start
    print(f"{args.draws} draws, bump {args.bump_mag} mag, truth {P_SID} s, {took:.1f} s")
    for name, got in rows.items():
        p, s = np.array(got).T
        pulls = (p - P_SID) / s
        print(
            f"{name:7s} applied {p.size}/{args.draws}: std(P)/median(std) "
            f"{np.std(p) / np.median(s):.3g}, bias/std(P) {(np.mean(p) - P_SID) / np.std(p):+.3g}, "
            f"std of pulls {np.sqrt(np.mean(pulls**2)):.3g}, median std {np.median(s):.3g} s"
        )


if __name__ == "__main__":
    main()
