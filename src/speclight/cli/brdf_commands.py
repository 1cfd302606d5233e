"""The command of lab BRDF tables: ``brdf-fit`` (speclight.target.brdf_fit)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from speclight.cli.flags import flag_names
from speclight.cli.guard import guarded
from speclight.cli.options import Force, Plot, output_option, say_wrote, write_products

#: Python parameter -> flag of the fit ``brdf-fit`` calls.
BRDF_FIT_FLAGS = {
    "model": "--model", "distribution": "--distribution", "fresnel": "--fresnel",
    "min_brdf": "--min-brdf",
}  # fmt: skip


def brdf_fit(
    table: Annotated[
        str,
        typer.Argument(
            help="Measured in-plane BRDF table: a CSV (phi_i theta_i phi_o theta_o brdf, deg "
            "and sr-1) or a shipped table name."
        ),
    ],
    model: Annotated[
        str, typer.Option("--model", help="Analytic model: phong, abg, binomial or microfacet.")
    ],
    output: Annotated[str, output_option("FILE", "Material YAML.")] = "material.yaml",
    distribution: Annotated[
        str, typer.Option("--distribution", help="microfacet: ggx or beckmann.")
    ] = "ggx",
    fresnel: Annotated[
        str, typer.Option("--fresnel", help="microfacet: schlick or exact (a dielectric).")
    ] = "schlick",
    min_brdf: Annotated[
        float,
        typer.Option("--min-brdf", help="Leave out samples at or below this BRDF \\[sr-1]."),
    ] = 0.0,
    plot_file: Plot = None,
    force: Force = False,
) -> None:
    """Fit an analytic BRDF model to a measured table in log space, print the residual per
    incidence angle and write the model as a material for a scenario's target.materials
    (its directional albedo held at most 1). See docs/brdf-models.md.

    Example: speclight brdf-fit starlink_v1p5_chassis_532nm --model binomial -o chassis.yaml
    """

    def run() -> None:
        from speclight.target.brdf_fit.log_fit import fit_table_samples
        from speclight.target.brdf_fit.material_yaml import material_yaml, report_lines
        from speclight.target.brdf_samples import read_table_samples

        def fit() -> tuple[Any, Any]:
            samples = read_table_samples(table)
            with flag_names(**BRDF_FIT_FLAGS):
                return samples, fit_table_samples(samples, model, distribution, fresnel, min_brdf)

        def draw(found: tuple[Any, Any]) -> Any:
            from speclight.plot.brdf_fit_figure import brdf_fit_figure

            return brdf_fit_figure(*found)

        _, result = write_products(
            output, plot_file, force, {"table": table} if Path(table).exists() else {},
            compute=fit, data=lambda found: material_yaml(found[1]).encode(), figure=draw,
        )  # fmt: skip
        for line in report_lines(result):
            typer.echo(line)
        say_wrote(output, plot_file)

    guarded(run)
