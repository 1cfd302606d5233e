"""The ``speclight`` command line (SPEC section 2).

Exit codes: 0 success, 2 bad input (the message names the file, the field and what is
accepted), 1 internal error or an output the file system refused (full disk).
"""

from __future__ import annotations

import sys
import traceback
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any

import typer

from speclight.errors import InputError
from speclight.io.output import OutputWriteError

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="Spectral light curves of satellites and space debris, as a ground telescope sees them.",
    pretty_exceptions_enable=False,
)


def _fail(message: str, code: int) -> None:
    typer.echo(f"error: {message}", err=True)
    raise typer.Exit(code)


def _guarded(func: Callable[[], Any]) -> Any:
    try:
        return func()
    except InputError as exc:
        _fail(str(exc), 2)
    except OutputWriteError as exc:
        _fail(str(exc), 1)
    except KeyboardInterrupt:
        _fail("interrupted", 130)
    except typer.Exit:
        raise
    except Exception:  # an internal error: say so, with the traceback for a bug report
        traceback.print_exc()
        _fail("internal error (please report it with the traceback above)", 1)


@app.command()
def simulate(
    scenario: Annotated[
        Path | None, typer.Argument(help="Scenario YAML file (see `speclight example`).")
    ] = None,
    output: Annotated[Path, typer.Option("--output", "-o", help="Output NetCDF file.")] = Path(
        "speclight.nc"
    ),
    example: Annotated[
        str | None, typer.Option("--example", help="Run a built-in scenario instead of a file.")
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Overwrite an existing output.")] = False,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="Print nothing but errors.")] = False,
) -> None:
    """Run one scenario and write its NetCDF dataset (geometry, spectra, bands) to OUTPUT.

    OUTPUT is claimed before the work starts: a bad folder, the scenario file itself, an
    existing file without --force, or another run writing it is refused at once (exit 2).
    """

    def run() -> None:
        from speclight.io.output import OutputClaim

        if (scenario is None) == (example is None):
            raise InputError("give a scenario file or --example NAME (one of them)")
        inputs = {"scenario file": scenario} if scenario is not None else {}
        with OutputClaim(output, force=force, inputs=inputs) as claim:
            from speclight.io.netcdf import dataset_bytes
            from speclight.scenario import load_example, load_scenario
            from speclight.simulate import simulate as run_simulation

            loaded = load_example(example) if example else load_scenario(scenario)  # type: ignore[arg-type]
            result = run_simulation(loaded, progress=sys.stderr.isatty() and not quiet)
            claim.write(dataset_bytes(result.dataset))
        if not quiet:
            for note in result.notes:
                typer.echo(note)
            typer.echo(f"wrote {output}")

    _guarded(run)


@app.command("example")
def example_cmd(
    name: Annotated[str | None, typer.Argument(help="Name of a built-in scenario.")] = None,
) -> None:
    """Print a built-in scenario as YAML (without NAME: list them)."""

    def run() -> None:
        from speclight.scenario import example_names, example_text

        if name is None:
            typer.echo("\n".join(example_names()))
        else:
            typer.echo(example_text(name), nl=False)

    _guarded(run)


@app.command()
def plot(
    dataset: Annotated[Path, typer.Argument(help="A dataset written by `speclight simulate`.")],
    output: Annotated[Path, typer.Option("--output", "-o", help="Figure file (.png, .pdf).")] = (
        Path("speclight.png")
    ),
    epoch: Annotated[
        str | None,
        typer.Option(
            "--epoch",
            help="Epoch of the chain figure: index or UTC time (default: brightest observable).",
        ),
    ] = None,
    band: Annotated[
        str | None, typer.Option("--band", help="Band of the radiance images (default: first).")
    ] = None,
    kind: Annotated[
        list[str] | None,
        typer.Option(
            "--kind",
            help="Figures to write: overview, chain, images, ranging (repeatable; default: all "
            "that the data can fill; the overview is always written).",
        ),
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Overwrite existing figures.")] = False,
) -> None:
    """Plot a dataset: light curves, spectrogram and geometry in OUTPUT; the one-epoch chain,
    images and ranging figures beside it (OUTPUT-chain.png, ...)."""

    def run() -> None:
        from speclight.plot import plot_files

        chosen: int | str | None = epoch
        if epoch is not None and epoch.strip().lstrip("-").isdigit():
            chosen = int(epoch)
        kinds = None if not kind else ["overview", *[k for k in kind if k != "overview"]]
        written = plot_files(dataset, output, force=force, epoch=chosen, band=band, kinds=kinds)
        for path in written:
            typer.echo(f"wrote {path}")

    _guarded(run)


@app.command()
def info() -> None:
    """Versions of speclight and its engines, render variants, and data coverage."""

    def run() -> None:
        from speclight.info import info_report

        for section, entries in info_report().items():
            typer.echo(f"{section}:")
            width = max(len(k) for k in entries)
            for key, value in entries.items():
                typer.echo(f"  {key:<{width}}  {value}")

    _guarded(run)


def _one_line_notice(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    line: str | None = None,
) -> str:
    return f"notice: {message}\n"


def main() -> None:
    """Console-script entry point."""
    warnings.formatwarning = _one_line_notice  # fallbacks are notices, not tracebacks
    app()


if __name__ == "__main__":
    main()
