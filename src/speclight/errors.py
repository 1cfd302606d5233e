"""Exceptions raised by speclight.

Every error caused by what a user wrote (a scenario field, a table file, a TLE) is an
:class:`InputError`, a :class:`ValueError` whose message names the source, the field,
the offending value and what is accepted. The command line turns it into exit code 2.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable


class SpeclightError(Exception):
    """Base class of all speclight errors."""


class InputError(SpeclightError, ValueError):
    """Bad user input: a scenario field, a data file or a command-line value.

    Parameters
    ----------
    message
        What is wrong and what is accepted.
    source
        The file (or other origin) the value came from, if known.
    field
        Dotted path of the offending field, e.g. ``time.step_s``, if known.
    """

    def __init__(self, message: str, *, source: str | None = None, field: str | None = None):
        self.message = message
        self.source = source
        self.field = field
        super().__init__(self._format())

    def _format(self) -> str:
        where = ": ".join(part for part in (self.source, self.field) if part)
        return f"{where}: {self.message}" if where else self.message


def did_you_mean(value: str, choices: Iterable[str]) -> str:
    """Return a ``"; did you mean 'x'?"`` hint for a misspelt name, or ``""``."""
    close = difflib.get_close_matches(value, list(choices), n=1, cutoff=0.6)
    return f"; did you mean '{close[0]}'?" if close else ""
