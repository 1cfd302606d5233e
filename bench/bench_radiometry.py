"""Benchmark of the radiometry chain: atmosphere + instrument for 600 epochs x 189 bins.

Run: ``.venv/bin/python bench/bench_radiometry.py`` (warm 6S cache in the user cache;
the first run fills it) or ``... --cold`` to also time a cold 6S run in a fresh folder.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from speclight.atmosphere import cache_root, transmission
from speclight.instrument import (
    ab_magnitude,
    aperture_area_m2,
    band_response,
    count_rate_per_s,
    simulate_measurement,
    sky_count_rate_per_s,
    spectral_curve,
    spectral_flux_W_nm,
)

N_EPOCHS = 600
WL = np.arange(300.0, 1241.0, 5.0)  # 189 bins
BANDS = [
    "G-420/26", "G-531/26", "G-638/26", "G-750/26", "G-850/26", "G-950/26", "G-1069/26",
    "bessell-V", "sdss2010-r", "sdss2010-i",
]  # fmt: skip


def best_of(fn: Callable[[], Any], repeat: int = 5) -> tuple[float, Any]:
    """Best wall time of ``repeat`` calls [s] and the last result."""
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def instrument_chain(intensity: np.ndarray, t_atm: np.ndarray, range_m: np.ndarray) -> Any:
    area = aperture_area_m2(0.43, 0.1)
    optics = spectral_curve(0.8, WL, field="instrument.optics_transmission")
    qe = spectral_curve("hamamatsu-s10420-ccd", WL)
    bands = band_response(BANDS, WL)
    flux = spectral_flux_W_nm(intensity, t_atm, area, range_m)
    rate = count_rate_per_s(flux, WL, optics, qe, bands)
    mag = ab_magnitude(flux, area, WL, bands)
    sky = sky_count_rate_per_s(
        21.0, area, WL, optics, qe, bands, background_aperture_radius_arcsec=3.0
    )
    noisy = simulate_measurement(
        rate, 1.0, sky_count_rate_per_s=sky, dark_current_e_per_s=1.0, read_noise_e=5.0, seed=0
    )
    return rate, mag, noisy


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--cold", action="store_true", help="also time a cold 6S run")
    args = parser.parse_args()

    elevation = 10.0 + 70.0 * np.sin(np.linspace(0.0, np.pi, N_EPOCHS))
    range_m = 1.2e6 / np.sin(np.radians(elevation + 5.0))
    intensity = np.outer(np.linspace(1.0, 3.0, N_EPOCHS), 1.0 + 0.2 * np.sin(WL / 50.0))

    print(f"radiometry benchmark: {N_EPOCHS} epochs x {WL.size} bins, {len(BANDS)} bands")
    rows: list[tuple[str, float]] = []
    t, _ = best_of(lambda: transmission("spectrl2", WL, elevation, 355.0))
    rows.append(("transmission spectrl2", t))
    if args.cold:
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            transmission("6s", WL, elevation, 355.0, cache_dir=Path(tmp))
            rows.append(("transmission 6s COLD (fresh cache, 2 workers)", time.perf_counter() - t0))
    t0 = time.perf_counter()
    t_atm = transmission("6s", WL, elevation, 355.0)
    rows.append((f"transmission 6s first call (cache {cache_root()})", time.perf_counter() - t0))
    t, t_atm = best_of(lambda: transmission("6s", WL, elevation, 355.0))
    rows.append(("transmission 6s warm", t))
    t, _ = best_of(lambda: instrument_chain(intensity, t_atm, range_m))
    rows.append(("instrument chain (area, QE, bands, flux, rates, AB, sky, noise)", t))
    for name, seconds in rows:
        print(f"  {name:<70s} {seconds * 1e3:10.1f} ms")


if __name__ == "__main__":
    main()
