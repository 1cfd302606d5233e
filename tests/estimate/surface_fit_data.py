"""Synthetic observations of the ``starlink-v1.5`` example with Phong surfaces of known
coefficients, simulated by the full pipeline (``simulate``) at three Chilean sites, for
the tests of ``speclight fit --free brdf`` (docs/surface-fit.md)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import yaml

from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate

#: The true coefficients: the chassis underside and the array as Phong surfaces.
TRUTH = {"bus_nadir": {"kd": 0.3, "ks": 0.4, "n": 8.0}, "array": {"kd": 0.1, "ks": 0.3, "n": 20.0}}
#: A start far from the truth (factors 6-12 in every coefficient).
FAR_START = {
    "bus_nadir": {"kd": 0.05, "ks": 0.05, "n": 100.0},
    "array": {"kd": 0.5, "ks": 0.05, "n": 2.0},
}
#: Cerro Pachon, La Silla, Las Campanas (the same evening pass seen from each).
SITES = [(-30.2446, -70.7494, 2663.0), (-29.2567, -70.7377, 2400.0), (-29.0146, -70.6926, 2380.0)]
NOISE_MAG = 0.05
NOT_SEEN = 1 | 2 | 4 | 128  # orbit failed, below the minimum elevation, shadow, daylight


def scenario(coefficients: dict[str, dict[str, float]], resolution_px: int = 32) -> dict[str, Any]:
    """The example, small (32 px, 4 Earthshine cells, 25 nm, band V) with Phong surfaces
    (the bus's sides Lambertian 0.2, not fitted)."""
    d = yaml.safe_load(example_text("starlink-v1.5"))
    d["render"]["resolution_px"] = resolution_px
    d["spectrum"]["step_nm"] = 25.0
    d["time"]["step_s"] = 10.0
    d["illumination"]["earthshine"]["samples"] = 4
    d["instrument"]["bands"] = d["instrument"]["bands"][:1]
    d["observer"]["min_elevation_deg"] = 15
    d["target"]["materials"] = {
        "bus_nadir": {"bsdf": "phong", "coefficients": dict(coefficients["bus_nadir"])},
        "bus": {"bsdf": "lambertian", "reflectance": 0.2},
        "array": {"bsdf": "phong", "coefficients": dict(coefficients["array"])},
    }
    return d


def write_observations(path: Path, noise_mag: float = NOISE_MAG, seed: int = 1) -> np.ndarray:
    """OBSERVATIONS at every observable epoch of the pass at :data:`SITES` (the truth's
    magnitudes plus Gaussian noise of ``noise_mag``); returns the noise-free magnitudes."""
    truth = scenario(TRUTH)
    rng = np.random.default_rng(seed)
    lines = ["time,latitude_deg,longitude_deg,altitude_m,band,magnitude,magnitude_sigma"]
    clean = []
    for lat, lon, alt in SITES:
        truth["observer"].update(latitude_deg=lat, longitude_deg=lon, altitude_m=alt)
        ds = simulate(parse_scenario(yaml.safe_dump(truth))).dataset
        m = ds["ab_magnitude"].sel(band="V").values
        ok = np.isfinite(m) & ((ds["flags"].values & NOT_SEEN) == 0)
        for t, mag in zip(ds["time"].values[ok], m[ok], strict=True):
            noisy = mag + rng.normal(0.0, noise_mag)
            lines.append(f"{str(t)[:23]}Z,{lat},{lon},{alt},V,{noisy:.6f},{max(noise_mag, 1e-3)}")
            clean.append(mag)
    path.write_text("\n".join(lines) + "\n")
    return np.array(clean)


def write_scenario(path: Path, coefficients: dict[str, dict[str, float]]) -> Path:
    path.write_text(yaml.safe_dump(scenario(coefficients), sort_keys=False))
    return path
