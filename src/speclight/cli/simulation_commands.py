"""Commands of the forward model: ``simulate``, ``example``, ``passes`` (speclight.simulation)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated, Any

import typer

from speclight.cli.guard import guarded
from speclight.cli.options import (
    dataset_file,
    force_option,
    output_option,
    say_wrote,
    write_products,
)
from speclight.errors import InputError


def simulate(
    scenario: Annotated[
        Path | None, typer.Argument(help="Scenario YAML file (see `speclight example`).")
    ] = None,
    output: Annotated[str, output_option("FILE", "Output NetCDF file.")] = "speclight.nc",
    example: Annotated[
        str | None, typer.Option("--example", help="Run a built-in scenario instead of a file.")
    ] = None,
    force: Annotated[bool, force_option("Overwrite an existing output.")] = False,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="Print nothing but errors.")] = False,
) -> None:
    """Run one scenario and write its NetCDF dataset (geometry, spectra, bands) to OUTPUT.

    OUTPUT is claimed before the work starts: a bad name or folder, the scenario file itself,
    an existing file without --force, or another run writing it is refused at once (exit 2).
    """

    def run() -> None:
        if (scenario is None) == (example is None):
            raise InputError("give a scenario file or --example NAME (one of them)")

        def compute() -> Any:
            from speclight.scenario import load_example, load_scenario
            from speclight.simulation import simulate as run_simulation

            loaded = load_example(example) if example else load_scenario(scenario)  # type: ignore[arg-type]
            return run_simulation(loaded, progress=sys.stderr.isatty() and not quiet)

        inputs = {"scenario file": scenario} if scenario is not None else {}
        result = write_products(
            output, None, force, inputs, compute=compute, data=lambda r: dataset_file(r.dataset)
        )
        if not quiet:
            for note in result.notes:
                typer.echo(note)
            say_wrote(output)

    guarded(run)


def example(
    name: Annotated[str | None, typer.Argument(help="Name of a built-in scenario.")] = None,
) -> None:
    """Print a built-in scenario as YAML (without NAME: list them)."""

    def run() -> None:
        from speclight.scenario import example_names, example_text

        if name is None:
            typer.echo("\n".join(example_names()))
        else:
            typer.echo(example_text(name), nl=False)

    guarded(run)


def passes(
    scenario: Annotated[Path, typer.Argument(help="Scenario YAML: its orbit and observer.")],
    output: Annotated[str | None, output_option("FILE", "Also write PASSES.csv or .json.")] = None,
    start: Annotated[
        str | None,
        typer.Option(help="Search from this UTC time (ISO 8601); default the scenario's start."),
    ] = None,
    end: Annotated[
        str | None,
        typer.Option(help="Search until this UTC time (ISO 8601); default the scenario's stop."),
    ] = None,
    force: Annotated[bool, force_option("Overwrite an existing output.")] = False,
) -> None:
    """Rise, culmination and set of every pass of the target above observer.min_elevation_deg,
    with the parts where it is sunlit, the sky is dark (the Sun at or below
    observer.max_sun_elevation_deg) and both (observable). See docs/passes.md.

    Example: speclight passes calsphere.yaml --start 2020-02-29T18:00Z --end 2020-03-01T06:00Z
    """

    def run() -> None:
        from speclight.scenario import load_scenario
        from speclight.simulation.pass_search import parse_utc, scenario_passes
        from speclight.simulation.pass_table import (
            check_passes_output,
            passes_file_bytes,
            print_passes,
        )

        start_utc = parse_utc(start, "--start") if start is not None else None
        end_utc = parse_utc(end, "--end") if end is not None else None

        def find() -> tuple[Any, Any]:
            loaded = load_scenario(scenario)
            return loaded, scenario_passes(loaded, start_utc, end_utc)

        if output is None:
            loaded, result = find()
        else:
            suffix = check_passes_output(output)
            loaded, result = write_products(
                output, None, force, {"scenario file": scenario}, compute=find,
                data=lambda found: passes_file_bytes(found[1], found[0].scenario.name, suffix),
            )  # fmt: skip
        print_passes(result, f"passes of {loaded.scenario.name}")
        if output is not None:
            say_wrote(output)

    guarded(run)


__all__ = ["example", "passes", "simulate"]
