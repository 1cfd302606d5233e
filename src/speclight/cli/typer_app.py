"""The ``speclight`` typer application: its options, its commands in the order ``--help``
lists them, and the entry point (:func:`main`). The commands live one module per product
group (``*_commands.py``); what they share is in :mod:`.options`, :mod:`.guard` (exit codes,
signals) and :mod:`.flags` (the cores' parameter names as flags).
"""

from __future__ import annotations

import sys
import warnings
from collections.abc import Callable
from typing import Annotated, Any

import typer

from speclight.cli import (
    brdf_commands,
    dataset_commands,
    fitting_commands,
    info_commands,
    map_commands,
    rotation_commands,
    scale_commands,
    shape_commands,
    simulation_commands,
    spectra_commands,
)

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="Spectral light curves of satellites and space debris, as a ground telescope sees them.",
    pretty_exceptions_enable=False,
    context_settings={"help_option_names": ["-h", "--help"]},
)


def _print_version(value: bool) -> None:
    if value:
        from speclight import __version__

        typer.echo(f"speclight {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[
        bool,
        typer.Option(
            "--version",
            callback=_print_version,
            is_eager=True,
            help="Print the version and exit.",
        ),
    ] = False,
) -> None:
    """Spectral light curves of satellites and space debris, as a ground telescope sees them."""


#: The commands, in the order of ``speclight --help`` (README: the command table).
COMMANDS: list[tuple[str, Callable[..., None]]] = [
    ("simulate", simulation_commands.simulate),
    ("example", simulation_commands.example),
    ("plot", dataset_commands.plot),
    ("fit", fitting_commands.fit),
    ("upsample", spectra_commands.upsample),
    ("unmix", spectra_commands.unmix),
    ("reflection-map", map_commands.reflection_map),
    ("reflectivity-map", map_commands.reflectivity_map),
    ("spin-axis", rotation_commands.spin_axis),
    ("period", rotation_commands.period),
    ("sweep", scale_commands.sweep),
    ("compare", fitting_commands.compare),
    ("brdf-fit", brdf_commands.brdf_fit),
    ("passes", simulation_commands.passes),
    ("frames", dataset_commands.frames),
    ("shape", shape_commands.shape),
    ("info", info_commands.info),
    ("update-data", info_commands.update_data),
]
for _name, _command in COMMANDS:
    app.command(_name)(_command)


def _one_line_notice(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    line: str | None = None,
) -> str:
    return f"notice: {message}\n"


#: Notices printed by this process: their text, or the category of those said once whatever
#: their text (the Earth-orientation table's).
_shown_notices: set[object] = set()


def _show_notice_once(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: Any = None,
    line: str | None = None,
) -> None:
    """Print a warning as a one-line notice, once per process (Python's own "once per
    place" starts over whenever a library changes the warning filters)."""
    from speclight.orbit.staleness import EarthOrientationWarning

    key = category if issubclass(category, EarthOrientationWarning) else (category, str(message))
    if key in _shown_notices:
        return
    _shown_notices.add(key)
    stream = sys.stderr if file is None else file
    try:
        stream.write(_one_line_notice(message, category, filename, lineno, line))
    except OSError:  # stderr closed: a notice is not worth failing for
        pass


def main() -> None:
    """Console-script entry point."""
    warnings.formatwarning = _one_line_notice  # fallbacks are notices, not tracebacks
    warnings.showwarning = _show_notice_once
    app(prog_name="speclight")
