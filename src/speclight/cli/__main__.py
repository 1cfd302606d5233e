"""``python -m speclight.cli``: the command line (``speclight --help``)."""

from speclight.cli import main

main()
