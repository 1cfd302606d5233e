"""Commands of spectra from bands: ``upsample`` and ``unmix`` (speclight.estimate.spectra)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated, Any

import typer

from speclight.cli.flags import flag_names
from speclight.cli.guard import guarded
from speclight.cli.options import (
    BinS,
    Force,
    MeasuredAndEndmembers,
    Plot,
    dataset_file,
    endmember_files,
    endmembers_option,
    measured_inputs,
    method_option,
    optional_scenario,
    output_option,
    say_wrote,
    scenario_option,
    source_option,
    write_products,
)

#: Python parameter -> flag of the cores ``unmix`` calls.
UNMIX_FLAGS = {
    "endmembers": "--endmembers", "extract": "--extract", "n": "--n", "method": "--method",
    "loaded": "--scenario", "bin_s": "--bin-s", "light": "--source",
}  # fmt: skip


def upsample(
    scenario: Annotated[Path, typer.Argument(help="Scenario YAML file: bands, optics, QE, grid.")],
    fit: Annotated[Path, typer.Argument(help="JSON with bands.BAND.albedo (`speclight fit`).")],
    output: Annotated[str, output_option("FILE", "Output CSV spectrum.")] = "spectrum.csv",
    plot_file: Plot = None,
    force: Force = False,
) -> None:
    """Reflectance spectrum from band albedos: a sigmoid of a polynomial of order n-1 whose
    photon-weighted band averages (band x optics x QE) equal the albedos (paper eq. 3-4).

    Writes CSV wavelength_nm,reflectance on the scenario's wavelength grid.
    """

    def run() -> None:
        from speclight.estimate.spectra.upsample_run import read_fit_albedos, spectrum_csv
        from speclight.estimate.spectra.upsample_run import upsample_scenario as upsample_from
        from speclight.scenario import load_scenario

        def draw(result: Any) -> Any:
            from speclight.plot.upsample_figure import upsample_figure

            return upsample_figure(result, scenario.stem)

        result = write_products(
            output, plot_file, force, {"scenario file": scenario, "fit file": fit},
            compute=lambda: upsample_from(
                load_scenario(scenario), read_fit_albedos(fit), str(fit)
            ),
            data=lambda r: spectrum_csv(r, str(scenario), str(fit)).encode(), figure=draw,
        )  # fmt: skip
        if not result.spectrum.converged:
            typer.echo(
                "notice: the fit did not converge: the spectrum reproduces the albedos only to "
                f"{result.spectrum.max_band_error:.3g} (said in the CSV header)"
            )
        say_wrote(output, plot_file)

    guarded(run)


def unmix(
    measured: MeasuredAndEndmembers,
    endmembers: Annotated[
        list[str] | None,
        endmembers_option(
            "Endmember spectrum CSV (wavelength_nm,reflectance; name = file stem); "
            "repeat for each, or 'scenario' for the scenario's materials."
        ),
    ] = None,
    extract: Annotated[
        str | None,
        typer.Option("--extract", help="Extract endmembers from the data: atgp, pca or nfindr."),
    ] = None,
    n: Annotated[int | None, typer.Option("--n", help="Number of endmembers to extract.")] = None,
    method: Annotated[str, method_option("ls, nnls, nnls-norm (default) or fcls.")] = "nnls-norm",
    scenario: Annotated[
        Path | None,
        scenario_option(
            "Scenario YAML (needed for a CSV; for a NetCDF default: the one it carries)."
        ),
    ] = None,
    bin_s: BinS = None,
    source: Annotated[
        str | None,
        source_option(
            "sun or laser: unmix the solar or the laser reflectance factors (default: "
            "the lasers' where the data have no solar ones)."
        ),
    ] = None,
    output: Annotated[str, output_option("FILE", "Output NetCDF (ABUND.nc).")] = "abundance.nc",
    plot_file: Plot = None,
    force: Force = False,
) -> None:
    """Per-epoch material contributions from band reflectance factors: the linear mixing
    model x = S a (paper eq. 6) with endmember spectra (-e FILE ..., or -e scenario for the
    scenario's materials) or endmembers extracted from the data (--extract, --n). Spectra
    enter through band signatures weighted by the source at the aperture (Sun or lasers),
    per epoch. Writes ABUND.nc: abundance(time, endmember), residual(time),
    endmember_signature(endmember, band) and reflectance_factor(time, band); with ground
    truth in MEASURED, the confusion matrix.

    Example: speclight unmix out.nc -e gold.csv cell.csv paint.csv -o abund.nc --plot abund.png
    """

    def run() -> None:
        from speclight.estimate.spectra.unmix_run import check_unmix_options, unmix_measured

        members = endmember_files(measured, endmembers)
        with flag_names(**UNMIX_FLAGS):
            check_unmix_options(
                endmembers=members, extract=extract, n=n, method=method, light=source
            )
        ds = write_products(
            output, plot_file, force, measured_inputs(measured[0], scenario, members),
            compute=lambda: unmix_measured(
                measured[0], endmembers=members, extract=extract, n=n, method=method,
                loaded=optional_scenario(scenario), bin_s=bin_s,
                progress=sys.stderr.isatty(), light=source,
            ),
            data=dataset_file, figure=_unmix_figure, flags=UNMIX_FLAGS,
        )  # fmt: skip
        if "mean_absolute_share_error" in ds.attrs:
            typer.echo(
                f"against the ground truth: mean absolute share error "
                f"{ds.attrs['mean_absolute_share_error']:.3f} (matched {ds.attrs['matching']})"
            )
        say_wrote(output, plot_file)

    guarded(run)


def _unmix_figure(ds: Any) -> Any:
    from speclight.plot.unmix_figure import unmix_figure

    return unmix_figure(ds)
