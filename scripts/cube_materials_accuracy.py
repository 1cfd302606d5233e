"""Unmixing accuracy of the cube-materials examples (reference paper section 5.2, Figure 13).

Runs ``cube-materials`` (Sun) and ``cube-materials-laser`` (seven coaxial laser lines),
unmixes the band reflectance factors against the four shipped material tables
(``nnls-norm`` and ``fcls``), compares with the ground truth of
``render: {per_material: true}`` and prints, for noise-free and noisy data, the
dominant-material confusion matrix (rows true, columns estimated) and the mean absolute error
of the fractions; then the ATGP signatures' spectral angles to the true ones and the
condition number of the band signature matrix. ``docs/cube-materials.md`` quotes its output::

    python scripts/cube_materials_accuracy.py [--resolution PX]

Noisy data. Under the Sun: the simulate output's ``count_rate_measured`` (the example's
noise block: Poisson, sky, dark current, read noise, 1 s exposures), as reflectance factors
(the factor is proportional to the rate). Under lasers the pipeline draws no noise for the
returns, so the same noise model (:func:`speclight.instrument.simulate_measurement`, the
example's noise block and sky) is applied here to ``return_rate``.
"""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np
import yaml

from speclight import instrument
from speclight.estimate import extract_endmembers
from speclight.estimate.ground_truth import (
    coaxial_laser_source_W_m2_nm,
    fractions,
    matched_angles_deg,
    material_signatures,
    mean_source_W_m2_nm,
    true_contributions,
    unmix_accuracy,
)
from speclight.illumination.laser import gaussian_line_per_nm
from speclight.scenario import example_text, parse_scenario
from speclight.simulate import simulate
from speclight.simulate.ranging_stage import SUPPORT_THRESHOLD
from speclight.target import Reflectance
from speclight.target.material_tables import MATERIAL_TABLES, material_table_path

NAMES = list(MATERIAL_TABLES)  # aluminium, kapton_mli, solar_cell, white_paint


def run(name: str, resolution_px: int | None) -> tuple[Any, Any]:
    """The example's scenario (optionally at another resolution) and its output dataset."""
    d = yaml.safe_load(example_text(name))
    if resolution_px:
        d["render"]["resolution_px"] = resolution_px
    loaded = parse_scenario(yaml.safe_dump(d), source=name)
    return loaded, simulate(loaded).dataset


def case(loaded: Any, ds: Any, laser: bool, seed: int = 7) -> dict[str, Any]:
    """Signatures, factors (noise-free and noisy) and true fractions of one run."""
    wl = ds["wavelength"].values
    response = (
        ds["band_response"].values * ds["detector_qe"].values * ds["optics_transmission"].values
    )
    tables = np.stack([Reflectance.table_file(material_table_path(n)).evaluate(wl) for n in NAMES])
    transmission = ds["transmission"].values
    if laser:
        lasers = loaded.scenario.illumination.lasers
        lines = np.stack(
            [gaussian_line_per_nm(wl, la.wavelength_nm, la.linewidth_nm) for la in lasers]
        )
        keep = lines > SUPPORT_THRESHOLD * lines.max(axis=1, keepdims=True)
        lines = np.where(keep, lines, 0.0)  # on their support, as the pipeline keeps them
        at_aperture = coaxial_laser_source_W_m2_nm(
            ds["laser_irradiance"].values, lines, transmission
        )
        source = mean_source_W_m2_nm(at_aperture, 1.0)
        x = ds["laser_reflectance_factor"].values
        per_material = ds["laser_reflectance_factor_material"].values
        rate = ds["return_rate"].values
        noise = loaded.scenario.instrument.noise
        area = instrument.aperture_area_m2(0.43, 0.0)
        sky = instrument.sky_count_rate_per_s(
            noise.sky_background_mag_arcsec2,
            area,
            wl,
            np.ones(wl.size),
            np.ones(wl.size),
            response,
            background_aperture_radius_arcsec=noise.aperture_radius_arcsec,
        )
        finite = np.isfinite(rate)
        measured = np.full_like(rate, np.nan)
        measured[finite] = instrument.simulate_measurement(
            rate[finite],
            loaded.scenario.instrument.exposure_s,
            sky_count_rate_per_s=np.broadcast_to(sky, rate.shape)[finite],
            dark_current_e_per_s=noise.dark_current_e_per_s,
            read_noise_e=noise.read_noise_e,
            seed=seed,
        )
    else:
        source = mean_source_W_m2_nm(
            ds["solar_irradiance"].values, transmission, ds["sunlit"].values
        )
        x = ds["reflectance_factor"].values
        per_material = ds["reflectance_factor_material"].values
        rate, measured = ds["count_rate"].values, ds["count_rate_measured"].values
    with np.errstate(invalid="ignore", divide="ignore"):
        noisy = np.where(rate > 0, x * measured / rate, np.nan)
    signatures = material_signatures(tables, response, wl, source)
    labels = [str(v) for v in ds["material_reflectance"].values]
    truth = fractions(true_contributions(per_material, labels, NAMES, signatures))
    plain = material_signatures(tables, response, wl)  # band_albedo: no source weighting
    return {"x": x, "noisy": noisy, "truth": truth, "signatures": signatures, "plain": plain}


def report(title: str, c: dict[str, Any]) -> None:
    print(f"\n## {title}")
    cond = np.linalg.cond(c["signatures"].T)
    purest = np.nanmax(c["truth"], axis=0)
    print(
        "purest epoch per material: "
        + ", ".join(f"{n} {p:.2f}" for n, p in zip(NAMES, purest, strict=True))
    )
    print(f"condition number of the signature matrix (10 x 4): {cond:.1f}")
    for data in ("x", "noisy"):
        for method in ("nnls-norm", "fcls"):
            for sig in ("signatures", "plain"):
                acc = unmix_accuracy(c[data], c["truth"], c[sig], method)  # type: ignore[arg-type]
                kind = "noise-free" if data == "x" else "noisy"
                weights = "source-weighted" if sig == "signatures" else "band_albedo"
                print(
                    f"\n{kind}, {method}, {weights} signatures: {acc.n_epochs} epochs, "
                    f"dominant material right {100 * acc.dominant_accuracy:.1f} %, "
                    f"mean |error| {acc.mean_abs_error:.2e}, max {acc.max_abs_error:.2e}"
                )
                if sig == "signatures" and method == "nnls-norm":
                    print("true \\ estimated: " + " ".join(f"{n:>11}" for n in NAMES))
                    for n, row in zip(NAMES, acc.confusion, strict=True):
                        print(f"{n:>17}: " + " ".join(f"{v:>11d}" for v in row))
    for data in ("x", "noisy"):
        for method in ("atgp", "nfindr"):
            ext = extract_endmembers(c[data], 4, method=method)  # type: ignore[arg-type]
            angle, _ = matched_angles_deg(c["signatures"], ext.signatures)
            kind = "noise-free" if data == "x" else "noisy"
            pairs = ", ".join(f"{n} {a:.2f}" for n, a in zip(NAMES, angle, strict=True))
            print(f"\n{method} ({kind}): spectral angle to the true signature [deg]: {pairs}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--resolution", type=int, default=None, help="render.resolution_px")
    args = parser.parse_args()
    np.set_printoptions(precision=4, suppress=True)
    loaded, ds = run("cube-materials", args.resolution)
    report("cube-materials (Sun)", case(loaded, ds, laser=False))
    loaded, ds = run("cube-materials-laser", args.resolution)
    report("cube-materials-laser (seven coaxial laser lines)", case(loaded, ds, laser=True))


if __name__ == "__main__":
    main()
