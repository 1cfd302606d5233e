"""``python -m speclight``: the command line (``speclight --help``)."""

from speclight.cli import main

main()
