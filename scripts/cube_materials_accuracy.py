"""Unmixing accuracy of the cube-materials examples (reference paper section 5.2, Figure 13).

Runs ``cube-materials`` (Sun) and ``cube-materials-laser`` (seven coaxial laser lines),
reads them back as ``speclight unmix`` does (:func:`speclight.estimate.
read_reflectance_factors`: the factors and the source spectrum at the aperture), makes the
four shipped material tables endmembers as ``speclight unmix -e TABLE.csv ...`` does
(:func:`speclight.estimate.endmembers_from_files`: signatures weighted by each epoch's
source, and by the mean source of the pass), unmixes (``nnls-norm`` and ``fcls``), compares
with the ground truth of ``render: {per_material: true}`` and prints, for noise-free and
noisy data, the dominant-material confusion matrix (rows true, columns estimated) and the
mean absolute error of the fractions, for per-epoch signatures (what ``speclight unmix``
uses), one matrix of the mean source spectrum, and plain ``band_albedo`` signatures without
the source; then the ATGP and N-FINDR signatures' spectral angles to the true ones and the
condition number of the band signature matrix. ``docs/cube-materials.md`` quotes its output::

    python scripts/cube_materials_accuracy.py [--resolution PX]

Noisy data. Under the Sun: the simulate output's ``count_rate_measured`` (the example's
noise block: Poisson, sky, dark current, read noise, 1 s exposures), as reflectance factors
(the factor is proportional to the rate; what ``speclight unmix`` reads). Under lasers the
pipeline draws no noise for the returns, so the same noise model
(:func:`speclight.instrument.simulate_measurement`, the example's noise block and sky) is
applied here to ``return_rate``.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from speclight import instrument
from speclight.estimate import (
    endmembers_from_files,
    extract_endmembers,
    fractions,
    material_signatures,
    read_reflectance_factors,
    true_contributions,
)
from speclight.estimate.spectra.ground_truth import matched_angles_deg, unmix_accuracy
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate
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
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "run.nc"
        ds.to_netcdf(path, engine="h5netcdf")
        data = read_reflectance_factors(path, loaded, light="laser" if laser else "sun")
    tables = [material_table_path(n) for n in NAMES]
    members = endmembers_from_files(tables, data.bands, data.source_W_m2_nm)
    if laser:
        x = ds["laser_reflectance_factor"].values
        rate = ds["return_rate"].values
        noise = loaded.scenario.instrument.noise
        wl = data.bands.wavelength_nm
        sky = instrument.sky_count_rate_per_s(
            noise.sky_background_mag_arcsec2,
            instrument.aperture_area_m2(0.43, 0.0),
            wl,
            np.ones(wl.size),
            np.ones(wl.size),
            data.bands.response,
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
        with np.errstate(invalid="ignore", divide="ignore"):
            noisy = np.where(rate > 0, x * measured / rate, np.nan)
    else:
        x = ds["reflectance_factor"].values
        noisy = data.factor  # from count_rate_measured, as speclight unmix reads it
    assert data.material_contribution is not None and data.material_labels is not None
    truth = fractions(
        true_contributions(
            data.material_contribution, data.material_labels, NAMES, members.signatures_epoch
        )
    )
    tables_on_grid = members.spectra
    plain = material_signatures(tables_on_grid, data.bands.response, data.bands.wavelength_nm)
    return {
        "x": x,
        "noisy": noisy,
        "truth": truth,
        "per-epoch": members.signatures_epoch,
        "mean": members.signatures,
        "plain": plain,
    }


SIGNATURES = {
    "per-epoch": "per-epoch source-weighted (speclight unmix)",
    "mean": "mean-source-weighted",
    "plain": "band_albedo (no source)",
}


def report(title: str, c: dict[str, Any]) -> None:
    print(f"\n## {title}")
    cond = np.linalg.cond(c["mean"].T)
    purest = np.nanmax(c["truth"], axis=0)
    print(
        "purest epoch per material: "
        + ", ".join(f"{n} {p:.2f}" for n, p in zip(NAMES, purest, strict=True))
    )
    print(f"condition number of the signature matrix (10 x 4): {cond:.1f}")
    for data in ("x", "noisy"):
        for method in ("nnls-norm", "fcls"):
            for sig, what in SIGNATURES.items():
                acc = unmix_accuracy(c[data], c["truth"], c[sig], method)  # type: ignore[arg-type]
                kind = "noise-free" if data == "x" else "noisy"
                print(
                    f"\n{kind}, {method}, {what} signatures: {acc.n_epochs} epochs, "
                    f"dominant material right {100 * acc.dominant_accuracy:.1f} %, "
                    f"mean |error| {acc.mean_abs_error:.2e}, max {acc.max_abs_error:.2e}"
                )
                if sig == "per-epoch" and method == "nnls-norm":
                    print("true \\ estimated: " + " ".join(f"{n:>11}" for n in NAMES))
                    for n, row in zip(NAMES, acc.confusion, strict=True):
                        print(f"{n:>17}: " + " ".join(f"{v:>11d}" for v in row))
    for data in ("x", "noisy"):
        for method in ("atgp", "nfindr"):
            ext = extract_endmembers(c[data], 4, method=method)  # type: ignore[arg-type]
            angle, _ = matched_angles_deg(c["mean"], ext.signatures)
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
