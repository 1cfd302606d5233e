"""Map lookup benchmark: CPU per ``ReflectivityMap.intensity_1au`` call.

Run: ``.venv/bin/python bench/bench_map_lookup.py [--nside 16] [--bands 8] [--points 120]
[--seconds 3]``

A synthetic map (HEALPix ``--nside`` ring directions, phase angles 0-180 deg every 10 deg,
32 rolls, ``--bands`` random intensities) read at ``--points`` random Sun and observer
directions; prints the mean process CPU per call over ``--seconds``. No store is written:
the lookup alone, as the tumbling fit's map light model and ``render.mode: map`` call it.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
from astropy_healpix import HEALPix

from speclight.maps.map_lookup import MapHeader, ReflectivityMap


def synthetic_map(nside: int, bands: int, seed: int = 0) -> ReflectivityMap:
    """A map of random intensities on ``nside`` ring directions, 19 phase angles, 32 rolls."""
    hp = HEALPix(nside, order="ring")
    lon, lat = hp.healpix_to_lonlat(np.arange(hp.npix))
    lon_r, lat_r = lon.rad, lat.rad
    d = np.stack([np.cos(lat_r) * np.cos(lon_r), np.cos(lat_r) * np.sin(lon_r), np.sin(lat_r)], 1)
    phase_deg, roll_deg = np.arange(0.0, 181.0, 10.0), np.arange(32) * 360.0 / 32
    rng = np.random.default_rng(seed)
    intensity = rng.random((hp.npix, phase_deg.size, roll_deg.size, bands)).astype(np.float32)
    names = [f"b{k}" for k in range(bands)]
    header = MapHeader(
        Path("synthetic"), nside, np.linspace(400.0, 900.0, bands), names, phase_deg, roll_deg, {}
    )
    return ReflectivityMap(header, d, intensity)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nside", type=int, default=16)
    ap.add_argument("--bands", type=int, default=8)
    ap.add_argument("--points", type=int, default=120)
    ap.add_argument("--seconds", type=float, default=3.0)
    args = ap.parse_args()
    m = synthetic_map(args.nside, args.bands)
    rng = np.random.default_rng(1)
    sun, obs = (rng.normal(size=(args.points, 3)) for _ in range(2))
    sun /= np.linalg.norm(sun, axis=1)[:, None]
    obs /= np.linalg.norm(obs, axis=1)[:, None]
    m.intensity_1au(sun, obs)  # warm: imports and the map's cached frames
    t0, calls = time.process_time(), 0
    while time.process_time() - t0 < args.seconds:
        m.intensity_1au(sun, obs)
        calls += 1
    ms = 1e3 * (time.process_time() - t0) / calls
    print(f"nside {args.nside}, {args.bands} bands, {args.points} points: {ms:.3f} ms CPU per call")


if __name__ == "__main__":
    main()
