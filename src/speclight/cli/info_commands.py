"""Commands about speclight itself: ``info`` (versions, variants, data coverage) and
``update-data`` (the Earth-orientation table)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from speclight.cli.guard import fail, guarded
from speclight.errors import InputError


def info() -> None:
    """Versions of speclight and its engines, render variants, and data coverage."""

    def run() -> None:
        from speclight.info import info_report

        for section, entries in info_report().items():
            typer.echo(f"{section}:")
            width = max(len(k) for k in entries)
            for key, value in entries.items():
                typer.echo(f"  {key:<{width}}  {value}")

    guarded(run)


def update_data(
    from_file: Annotated[
        Path | None,
        typer.Option("--from", metavar="FILE", help="Install this finals2000A.all (no network)."),
    ] = None,
    url: Annotated[
        str | None,
        typer.Option("--url", help="Download from here (default: the IERS Rapid Service)."),
    ] = None,
    timeout_s: Annotated[
        float, typer.Option("--timeout-s", help="Give up a download after this many seconds.")
    ] = 60.0,
) -> None:
    """Refresh the Earth-orientation and leap-second table (IERS finals2000A.all).

    Downloads it (or takes --from FILE), checks it and installs it in the user data folder
    ($SPECLIGHT_DATA_DIR, else ~/.local/share/speclight); runs use it from then on when it
    reaches further than the table shipped in skyfield-data. Nothing else downloads.
    """

    def run() -> None:
        from speclight.orbit.iers_update import DataUpdateError, update_from_file, update_from_url

        if from_file is not None and url is not None:
            raise InputError("give --from FILE or --url URL, not both", field="--from")
        if not 0 < timeout_s < float("inf"):
            raise InputError(f"--timeout-s = {timeout_s!r} must be > 0 s", field="--timeout-s")
        try:
            if from_file is not None:
                result = update_from_file(from_file)
            else:
                result = update_from_url(url, timeout_s)
        except DataUpdateError as exc:
            fail(str(exc), 1)
        cov = result.coverage
        typer.echo(
            f"installed {result.installed} from {result.source}: Earth orientation measured "
            f"until {cov.measured_until}, predicted (and leap seconds known) until "
            f"{cov.predicted_until}"
        )
        if result.in_use != result.installed:
            typer.echo(f"notice: {result.in_use} reaches further and stays in use", err=True)

    guarded(run)
