"""``speclight period`` against a plain astropy ``LombScargle`` (issue 26 item 2;
BENCHMARKS.md, "Period: cost against astropy").

A CSV of 10,000 epochs at 1 s in 3 bands (a 37 s three-harmonic light curve, SNR 30):
``estimate_period`` end to end (default: analytic false-alarm probability) and with
``fap_method="bootstrap"`` (40 draws, in parallel threads), against astropy's
``LombScargle(nterms=2)`` of each band on the same grid (12,485 frequencies from 1/(span/3)
to 1/4 Hz, 5 per peak width). Interleaved repeats; the median is reported.

Run: ``.venv/bin/python bench/bench_period_speed.py [--repeats 3] [--bootstrap]``
"""

from __future__ import annotations

import argparse
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

from speclight.estimate.period.period_options import SAMPLES_PER_PEAK
from speclight.estimate.period.period_run import estimate_period
from speclight.estimate.period.periodogram import frequency_grid


def light_curve(path: Path, n: int = 10_000) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(0)
    t = np.arange(float(n))
    ph = 2 * np.pi * t / 37.0
    mag = 0.3 * np.cos(ph) + 0.15 * np.cos(2 * ph + 0.7) + 0.2 * np.cos(3 * ph + 1.1)
    rate = 1e4 * 10 ** (-0.4 * (mag[:, None] + np.array([0.0, 0.1, 0.2])))
    sigma = rate / 30.0
    rate = rate + rng.normal(0, sigma)
    start = np.datetime64("2020-02-29T21:13:00", "s")
    lines = ["time,B,G,R,B_sigma,G_sigma,R_sigma"]
    for i in range(n):
        cells = [f"{v:.6g}" for v in (*rate[i], *sigma[i])]
        lines.append(f"{start + np.timedelta64(i, 's')}Z," + ",".join(cells))
    path.write_text("\n".join(lines) + "\n")
    mags = -2.5 * np.log10(rate)
    return t, mags, 2.5 / np.log(10) * sigma / rate


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--bootstrap", action="store_true", help="also time --fap bootstrap")
    args = parser.parse_args()
    from astropy.timeseries import LombScargle

    warnings.simplefilter("ignore")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "lc.csv"
        t, mag, dmag = light_curve(path)
        freq = frequency_grid(float(t[-1] - t[0]), 4.0, float(t[-1] - t[0]) / 3, SAMPLES_PER_PEAK)
        print(f"grid: {freq.size} frequencies, {t.size} epochs x 3 bands, K = 2")
        runs: dict[str, list[float]] = {"astropy": [], "period": [], "bootstrap": []}
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            for b in range(3):
                LombScargle(t, mag[:, b], dmag[:, b], nterms=2).power(freq, method="fastchi2")
            runs["astropy"].append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            result = estimate_period(path)
            runs["period"].append(time.perf_counter() - t0)
            if args.bootstrap:
                t0 = time.perf_counter()
                estimate_period(path, fap_method="bootstrap")
                runs["bootstrap"].append(time.perf_counter() - t0)
        assert result.frequency_hz.size == freq.size
        base = float(np.median(runs["astropy"]))
        for name, times in runs.items():
            if times:
                m = float(np.median(times))
                print(f"{name:10s} median {m:7.2f} s  ({m / base:5.2f} x astropy)  runs {times}")
        print(f"period found {result.period_s:.4f} s (truth 37 s or 74 s), verdict: "
              f"{result.verdict()[:60]}")  # fmt: skip


if __name__ == "__main__":
    main()
