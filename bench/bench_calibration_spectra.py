"""Calibration of unmix's uncertainties and misfit test on blind draws (issue 25 items 4-5).

Each draw picks, from its own seed: K = 3 or 4 of the four shipped material spectra
(aluminium, kapton_mli, solar_cell, white_paint) through the cube-materials example's ten
bands (photon-weighted band signatures, flat source), N = 200 epochs of random non-negative
mixtures (Dirichlet shares times a brightness 0.2-1), a noise level (SNR 30-300 at brightness
1), and a method (nnls, nnls-norm, fcls). It reports

* the standard deviation of ``(estimate - truth) / abundance_std`` over the contributions that
  are not at a bound (goal 0.8-1.25), the fraction within 3 sigma;
* the epochs marked as misfit with all endmembers (false alarms, expected 1e-3) and with one
  endmember left out (detections), and whether the set's note fired;
* ``purest`` against ``atgp`` extraction: the largest spectral angle to the true signatures
  when every material has 10 pure epochs among bright mixtures.

Run: ``.venv/bin/python bench/bench_calibration_spectra.py [--draws 60]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from speclight.estimate.inputs.band_responses import scenario_band_responses
from speclight.estimate.spectra.endmembers import extract_endmembers
from speclight.estimate.spectra.ground_truth import matched_angles_deg, material_signatures
from speclight.estimate.spectra.unmix_checks import unmix_checks
from speclight.estimate.spectra.unmixing import unmix
from speclight.scenario import example_text, parse_scenario
from speclight.target import Reflectance
from speclight.target.material_tables import MATERIAL_TABLES, material_table_path


def signatures() -> np.ndarray:
    bands = scenario_band_responses(parse_scenario(example_text("cube-materials")))
    spectra = [
        Reflectance.table_file(material_table_path(n)).evaluate(bands.wavelength_nm)
        for n in MATERIAL_TABLES
    ]
    return material_signatures(np.array(spectra), bands.response, bands.wavelength_nm)


def one_draw(seed: int, all_s: np.ndarray) -> dict[str, float]:
    rng = np.random.default_rng(seed)
    k = int(rng.integers(3, 5))
    s = all_s[rng.choice(4, size=k, replace=False)]
    method = str(rng.choice(["nnls", "nnls-norm", "fcls"]))
    n = 200
    share = rng.dirichlet(np.full(k, 3.0), size=n)
    brightness = rng.uniform(0.2, 1.0, (n, 1))
    a = share if method == "fcls" else share * brightness
    sigma_level = float(np.mean(s)) / rng.uniform(30, 300)
    sigma = np.full((n, s.shape[1]), sigma_level)
    x = a @ s + rng.normal(0.0, sigma)
    est = unmix(x, s, method).abundance  # type: ignore[arg-type]
    checks = unmix_checks(x, est, s, sigma, method)
    truth = share if method == "nnls-norm" else a
    inside = (est > 0) & (checks.abundance_std > 0)
    z = ((est - truth) / checks.abundance_std)[inside]
    drop = unmix(x, s[1:], method).abundance  # type: ignore[arg-type]
    missing = unmix_checks(x, drop, s[1:], sigma, method)
    pure = np.repeat(np.eye(k), 10, axis=0) * 0.2
    bright = rng.dirichlet(np.full(k, 2.0), size=300) * rng.uniform(0.5, 1.0, (300, 1))
    xe = np.vstack([pure, bright]) @ s
    se = np.full(xe.shape, sigma_level * 0.2)
    xe = xe + rng.normal(0.0, se)
    purest = matched_angles_deg(s, extract_endmembers(xe, k, "purest", se).signatures)[0]
    atgp = matched_angles_deg(s, extract_endmembers(xe, k, "atgp").signatures)[0]
    return {
        "z_std": float(np.std(z)),
        "z_in3": float(np.mean(np.abs(z) < 3)),
        "false_alarm": float(checks.misfit.mean()),
        "note_all": float(bool(checks.notes())),
        "detected": float(missing.misfit.mean()),
        "note_missing": float(any("missing" in t for t in missing.notes())),
        "purest_max_deg": float(np.max(purest)),
        "atgp_max_deg": float(np.max(atgp)),
    }


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--draws", type=int, default=60)
    args = parser.parse_args()
    t0 = time.perf_counter()
    all_s = signatures()
    rows = [one_draw(1000 + i, all_s) for i in range(args.draws)]
    keys = rows[0].keys()
    table = {key: np.array([r[key] for r in rows]) for key in keys}
    z = table["z_std"]
    print(f"{args.draws} draws in {time.perf_counter() - t0:.1f} s")
    print(f"(est - truth)/sigma std: median {np.median(z):.3f}, range {z.min():.3f}-{z.max():.3f}")
    print(f"  draws with std in 0.8-1.25: {np.mean((z >= 0.8) & (z <= 1.25)):.0%}")
    print(f"  fraction |z| < 3: {np.mean(table['z_in3']):.4f}")
    print(f"misfit epochs, all endmembers: {np.mean(table['false_alarm']):.2e} (expected 1e-3)")
    print(f"  set note fired with all endmembers: {np.mean(table['note_all']):.0%} of draws")
    print(f"misfit epochs, one endmember left out: {np.mean(table['detected']):.2f}")
    print(f"  'missing' note fired: {np.mean(table['note_missing']):.0%} of draws")
    for key in ("purest_max_deg", "atgp_max_deg"):
        v = table[key]
        print(f"{key}: median {np.median(v):.2f}, 90th pct {np.percentile(v, 90):.2f}")
    print(
        f"purest within 3 deg: {np.mean(table['purest_max_deg'] < 3):.0%}, "
        f"atgp within 3 deg: {np.mean(table['atgp_max_deg'] < 3):.0%}"
    )


if __name__ == "__main__":
    main()
