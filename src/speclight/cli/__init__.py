"""The ``speclight`` command line (README: the command table; ``speclight --help``).

Thin layers over the packages: one module per product group (:mod:`.simulation_commands`,
:mod:`.dataset_commands`, :mod:`.fitting_commands`, :mod:`.spectra_commands`,
:mod:`.map_commands`, :mod:`.rotation_commands`, :mod:`.shape_commands`,
:mod:`.brdf_commands`, :mod:`.scale_commands`, :mod:`.info_commands`), assembled in
:mod:`.typer_app`. Exit codes and signals: :mod:`.guard`.
"""

from speclight.cli.flags import cli_words
from speclight.cli.typer_app import app, main

__all__ = ["app", "cli_words", "main"]
