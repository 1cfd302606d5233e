"""What the commands share: their common options, their inputs, and the output step.

Every estimation command claims ``-o OUT`` and ``--plot FIG`` before any work, computes,
writes both or neither, and says what it wrote (:func:`write_products`, :func:`say_wrote`);
its options are declared once here (:func:`output_option`, :data:`Force`, :data:`Plot`...).
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Annotated, Any, TypeVar

import typer

from speclight.cli.flags import flag_names
from speclight.cli.guard import raise_if_signalled
from speclight.errors import InputError

T = TypeVar("T")


def output_option(metavar: str, help: str) -> Any:
    """``--output/-o``: where the command writes."""
    return typer.Option("--output", "-o", metavar=metavar, help=help)


def force_option(help: str = "Overwrite existing outputs.") -> Any:
    """``--force``: replace what the command would refuse to overwrite."""
    return typer.Option("--force", help=help)


def plot_option(help: str = "Figure (.png, .pdf, .svg).", metavar: str = "FIG") -> Any:
    """``--plot``: the command's figure, claimed with its output."""
    return typer.Option("--plot", metavar=metavar, help=help)


def scenario_option(help: str) -> Any:
    """``--scenario``: an optional scenario YAML (what it is for differs per command)."""
    return typer.Option("--scenario", help=help)


def bin_s_option(help: str = "Average epochs into bins of S seconds.") -> Any:
    """``--bin-s``: average the measured epochs into bins."""
    return typer.Option("--bin-s", help=help)


def source_option(help: str) -> Any:
    """``--source``: the light of the measurements, sun or laser."""
    return typer.Option("--source", help=help)


def endmembers_option(help: str) -> Any:
    """``--endmembers/-e``: endmember spectrum files, or 'scenario'."""
    return typer.Option("--endmembers", "-e", metavar="FILE", help=help)


def method_option(help: str) -> Any:
    """``--method``: the command's method by name."""
    return typer.Option("--method", help=help)


Force = Annotated[bool, force_option()]
Plot = Annotated[str | None, plot_option()]
BinS = Annotated[float | None, bin_s_option()]
#: ``MEASURED [E2.csv ...]``: the measured file, then more ``--endmembers`` files.
MeasuredAndEndmembers = Annotated[
    list[Path],
    typer.Argument(
        help="MEASURED first: a speclight NetCDF, or a CSV of count rates (with "
        "--scenario); any further arguments are more --endmembers files.",
        metavar="MEASURED [E2.csv ...]",
    ),
]


def measured_inputs(
    measured: Path, scenario: Path | None, endmembers: list[str] | None = None
) -> dict[str, Path | str]:
    """The input files of an estimation command, named for the output claim's checks."""
    inputs: dict[str, Path | str] = {"measured file": measured}
    if scenario is not None:
        inputs["scenario file"] = scenario
    for i, path in enumerate(endmembers or []):
        inputs[f"endmember file {i + 1}"] = path
    return inputs


def optional_scenario(scenario: Path | None) -> Any:
    """The loaded scenario of an optional ``--scenario``, or None."""
    if scenario is None:
        return None
    from speclight.scenario import load_scenario

    return load_scenario(scenario)


def endmember_files(arguments: list[Path], endmembers: list[str] | None) -> list[str] | None:
    """``--endmembers E1.csv E2.csv ...``: the files after the first arrive as
    positional arguments after MEASURED; ``-e`` may also be repeated."""
    extra = [str(p) for p in arguments[1:]]
    if extra and not endmembers:
        raise InputError(
            f"unexpected argument(s) {' '.join(extra)}: give one MEASURED file (endmember "
            "files follow --endmembers)",
            field="MEASURED",
        )
    return None if not endmembers else [*endmembers, *extra]


def json_bytes(data: Any) -> bytes:
    """A JSON output file's bytes (indented, one final newline)."""
    return (json.dumps(data, indent=2) + "\n").encode()


def dataset_file(ds: Any) -> bytes | memoryview:
    """A NetCDF output file's bytes (:func:`speclight.io.netcdf.dataset_bytes`)."""
    from speclight.io.netcdf import dataset_bytes

    return dataset_bytes(ds)


def write_products(
    output: str,
    plot_file: str | None,
    force: bool,
    inputs: Mapping[str, Path | str],
    *,
    compute: Callable[[], T],
    data: Callable[[T], bytes | memoryview],
    figure: Callable[[T], Any] | None = None,
    flags: Mapping[str, str] | None = None,
) -> T:
    """Claim OUTPUT (and the figure FIG), compute, then write both or neither.

    Parameters
    ----------
    output, plot_file, force
        The command's ``-o``, ``--plot`` and ``--force``.
    inputs
        The command's input files, which no output may be (their names for the messages).
    compute
        The command's work, run after the claims.
    data
        The output file's bytes from the result.
    figure
        The figure (a matplotlib figure) from the result, drawn where ``--plot`` is given.
    flags
        Python parameter -> flag of the cores the command calls (:func:`flag_names`).

    Returns
    -------
    The result of ``compute``.
    """
    from speclight.plot.figure_output import claim_outputs, write_outputs

    with (
        claim_outputs(output, plot_file, force, inputs) as (claim, claimed_figure),
        flag_names(**(flags or {})),
    ):
        result = compute()
        raise_if_signalled()
        draw = (lambda: figure(result)) if figure is not None else (lambda: None)
        write_outputs(claim, data(result), claimed_figure, draw)
    return result


def say_wrote(output: str, plot_file: str | None = None) -> None:
    """``wrote OUT`` (``and FIG``)."""
    typer.echo(f"wrote {output}" + (f" and {plot_file}" if plot_file else ""))
