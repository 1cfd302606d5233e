"""The command of many runs: ``sweep`` (speclight.scale)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated

import typer

from speclight.cli.guard import guarded, raise_if_signalled
from speclight.cli.options import force_option, output_option
from speclight.errors import InputError


def sweep(
    sweep_file: Annotated[
        Path, typer.Argument(metavar="SWEEP.yaml", help="Sweep file: base, vary, draws, seed.")
    ],
    output: Annotated[str, output_option("RUNS.zarr", "Output Zarr store.")] = "runs.zarr",
    scheduler: Annotated[
        str,
        typer.Option(
            "--scheduler",
            metavar="ADDRESS",
            help="local (a Dask cluster on this machine), none (in this process) or the "
            "address of a running scheduler, tcp://HOST:PORT.",
        ),
    ] = "local",
    workers: Annotated[
        int | None, typer.Option("--workers", help="Workers of the local cluster (default: cores).")
    ] = None,
    spectra: Annotated[
        bool, typer.Option("--spectra", help="Store intensity and spectral flux too.")
    ] = False,
    append: Annotated[
        bool, typer.Option("--append", help="Add the cases after those of an existing store.")
    ] = False,
    force: Annotated[bool, force_option("Replace an existing store.")] = False,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="Print nothing but errors.")] = False,
) -> None:
    """Run many variants of a scenario (grids and seeded random draws of any of its fields)
    on a Dask cluster and store every case's light curves in one Zarr store with a `case`
    dimension (docs/sweep.md). Every case is validated before any runs. Rerunning the same
    command resumes an interrupted sweep (done cases are skipped, failed ones retried); a
    failed case is recorded in error(case) and the others go on (a warning says how many;
    exit code 0); exit code 1 when every case failed.

    Example: speclight sweep docs/examples/sweep-calsphere.yaml -o runs.zarr --workers 2
    """

    def run() -> None:
        import dataclasses

        from speclight.scale.sweep_cases import plan_sweep
        from speclight.scale.sweep_file import load_sweep
        from speclight.scale.sweep_run import run_sweep

        if workers is not None and workers < 1:
            raise InputError(f"--workers = {workers} must be >= 1", field="--workers")
        spec = load_sweep(sweep_file)
        if spectra and not spec.spectra:
            spec = dataclasses.replace(spec, spectra=True)
        plan = plan_sweep(spec)
        result = run_sweep(
            plan,
            output,
            scheduler=scheduler,
            n_workers=workers,
            force=force,
            append=append,
            progress=sys.stderr.isatty() and not quiet,
            announce=not quiet,
        )
        raise_if_signalled()
        last = result.first_case + result.n_cases - 1
        if result.damaged:
            typer.echo(
                f"notice: {len(result.damaged)} case(s) marked done did not read back (case "
                f"{result.damaged[0]}: a file cut short): run again",
                err=True,
            )
        if not quiet:
            typer.echo(
                f"cases {result.first_case}..{last}: ran {result.ran}, skipped {result.skipped} "
                f"done before, in {result.seconds:.1f} s"
            )
        if result.failed:  # docs/sweep.md, "Failures": exit 1 if all failed, else 0
            index, message = next(iter(result.failed.items()))
            level = "error" if result.exit_code else "warning"
            typer.echo(
                f"{level}: {len(result.failed)} of {result.n_cases} case(s) failed (case {index}: "
                f"{message}); their rows are NaN and error(case) holds the message: rerun the "
                "same command to retry them",
                err=True,
            )
        if not quiet:
            typer.echo(f"wrote {output}")
        if result.exit_code:
            raise typer.Exit(result.exit_code)

    guarded(run)
