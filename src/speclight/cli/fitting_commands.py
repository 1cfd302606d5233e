"""Commands that run a scenario against measurements: ``fit`` (speclight.estimate.fitting)
and ``compare`` (speclight.estimate.comparison)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated, Any

import typer

from speclight.cli.flags import flag_names
from speclight.cli.guard import guarded
from speclight.cli.options import (
    Force,
    Plot,
    bin_s_option,
    dataset_file,
    json_bytes,
    method_option,
    output_option,
    plot_option,
    say_wrote,
    write_products,
)

#: Python parameter -> flag of the cores ``fit`` calls.
FIT_FLAGS = {
    "free": "--free",
    "method": "--method",
    "bin_s": "--bin-s",
    "clip_sigma": "--clip-sigma",
}


def fit(
    scenario: Annotated[Path, typer.Argument(help="Scenario YAML file (the fit's start).")],
    measured: Annotated[
        Path, typer.Argument(help="Measured light curves: CSV (time, <band>...) or NetCDF.")
    ],
    output: Annotated[str, output_option("FILE", "Output FIT.json.")] = "fit.json",
    free: Annotated[
        str,
        typer.Option(
            "--free",
            help="Parameters to fit: albedo, roughness or both (a,b); or, with OBSERVATIONS "
            "(magnitudes, as compare reads them), brdf or brdf,attitude.",
        ),
    ] = "albedo",
    bin_s: Annotated[
        float | None, bin_s_option("Average the measurements into S-second bins.")
    ] = None,
    plot_file: Annotated[
        str | None, plot_option("Figure: rates and ratios.", metavar="FIG.png")
    ] = None,
    method: Annotated[
        str,
        method_option(
            "Roughness fit: slsqp (central differences after a scan) or gradient "
            "(analytic derivatives; single-scattering render, beckmann/ggx materials)."
        ),
    ] = "slsqp",
    clip_sigma: Annotated[
        float,
        typer.Option(
            "--clip-sigma",
            help="Leave out (and name) measurements more than S robust sigmas from the fit "
            "(cosmic rays, glints the model lacks); 0 keeps every one.",
            metavar="S",
        ),
    ] = 5.0,
    force: Force = False,
) -> None:
    """Fit per-band albedos (with --free albedo,roughness also the roughness of every rough
    material) so that the scenario's count rates match MEASURED; write FIT.json.

    The scenario is simulated at the measured epochs, starting from its own reflectance and
    roughness. Outputs are claimed as `simulate` claims its output. See docs/fit.md.

    With --free brdf[,attitude] the second file is OBSERVATIONS (magnitudes per epoch and
    site, as `speclight compare` reads them) and the analytic BRDF coefficients of the
    target's surfaces (and a yaw offset) are fitted; output SURFACES.json, figure:
    residuals against phase angle. See docs/surface-fit.md.
    """
    names = [p.strip() for p in free.split(",") if p.strip()]
    if "brdf" in names or "attitude" in names:
        guarded(lambda: _fit_surfaces(scenario, measured, output, names, plot_file, force, bin_s))
        return

    def run() -> None:
        from speclight.estimate.fitting.fit_run import check_free, check_method, fit_scenario
        from speclight.estimate.inputs.measured import read_measured
        from speclight.scenario import load_scenario

        with flag_names(**FIT_FLAGS):
            names = check_free([p.strip() for p in free.split(",") if p.strip()])
            chosen = check_method(method)
        result = write_products(
            output, plot_file, force, {"scenario file": scenario, "measurements": measured},
            compute=lambda: fit_scenario(
                load_scenario(scenario), read_measured(measured), free=names, bin_s=bin_s,
                progress=sys.stderr.isatty(), method=chosen, clip_sigma=clip_sigma,
            ),
            data=lambda r: json_bytes(r.to_json()), figure=_fit_figure, flags=FIT_FLAGS,
        )  # fmt: skip
        if not result.converged:
            typer.echo(f"not converged: {result.message}", err=True)
        elif result.message != "ok":
            typer.echo(f"notice: {result.message}", err=True)
        albedos = zip(result.band_names, result.albedo, strict=True)
        typer.echo("albedo: " + ", ".join(f"{b} {a:.4g}" for b, a in albedos))
        for name, (value, std) in result.roughness.items():
            spread = f"+- {std:.2g}" if std == std else "(not constrained)"  # NaN: unconstrained
            typer.echo(f"roughness {name}: {value:.4g} {spread}")
        say_wrote(output, plot_file)

    guarded(run)


def _fit_surfaces(
    scenario: Path, observations: Path, output: str, names: list[str],
    plot_file: str | None, force: bool, bin_s: float | None,
) -> None:  # fmt: skip
    from speclight.errors import InputError
    from speclight.estimate.inputs.observations import read_observations
    from speclight.estimate.surface_fit import fit_surfaces
    from speclight.estimate.surface_fit.surface_fit_report import summary_lines
    from speclight.scenario import load_scenario

    if bin_s is not None:
        raise InputError(
            "it bins light curves; a BRDF fit takes magnitudes (leave it out)", field="--bin-s"
        )
    with flag_names(free="--free"):
        result = write_products(
            output, plot_file, force, {"scenario file": scenario, "observations": observations},
            compute=lambda: fit_surfaces(
                load_scenario(scenario), read_observations(observations), free=names,
                progress=sys.stderr.isatty(),
            ),
            data=lambda r: json_bytes(r.to_json()), figure=_surface_figure,
        )  # fmt: skip
    for line in summary_lines(result.summary):
        typer.echo(line)
    say_wrote(output, plot_file)


def _surface_figure(result: Any) -> Any:
    from speclight.plot.fit_figure import surface_fit_figure

    return surface_fit_figure(result)


def _fit_figure(result: Any) -> Any:
    from speclight.plot.fit_figure import fit_figure

    return fit_figure(
        result.time_utc, result.measured_per_s, result.fitted_per_s, result.band_names
    )


def compare(
    scenario: Annotated[
        Path, typer.Argument(help="Scenario YAML: target, attitude, orbit (or observed: true).")
    ],
    observations: Annotated[
        Path,
        typer.Argument(
            help="OBSERVATIONS CSV: time, site, magnitude, sigma, band (optional: position, "
            "object)."
        ),
    ],
    output: Annotated[str, output_option("FILE", "Output NetCDF (CMP.nc).")] = "compare.nc",
    plot_file: Plot = None,
    force: Force = False,
) -> None:
    """Simulate the scenario at every observed epoch and site (one run per site) and write
    observed, simulated and residual magnitudes with the geometry of each observation, and
    residual statistics with Pearson R and chi-square (also printed), per object too where
    the file has an object column (with orbit: {observed: true} each object's trajectory
    comes from its own rows). See docs/compare.md.

    Example: speclight compare calsphere.yaml observed.csv -o cmp.nc --plot cmp.png
    """

    def run() -> None:
        from speclight.estimate.comparison.compare_run import compare as run_compare
        from speclight.estimate.comparison.compare_stats import summary_lines
        from speclight.estimate.inputs.observations import read_observations
        from speclight.scenario import load_scenario

        result = write_products(
            output, plot_file, force,
            {"scenario file": scenario, "observations file": observations},
            compute=lambda: run_compare(
                load_scenario(scenario), read_observations(observations), sys.stderr.isatty()
            ),
            data=lambda r: dataset_file(r.dataset), figure=_compare_figure,
        )  # fmt: skip
        for line in [*result.notes, *summary_lines(result.dataset)]:
            typer.echo(line)
        say_wrote(output, plot_file)

    guarded(run)


def _compare_figure(result: Any) -> Any:
    from speclight.plot.compare_figure import compare_figure

    return compare_figure(result.dataset)
