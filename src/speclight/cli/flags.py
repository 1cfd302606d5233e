"""The plain-array cores name their Python parameters; the command line says its flags.

A core raises ``grid_deg = 0 must be in [0.01, 90]`` (STYLE.md item 16: a Python caller
reads the argument it passed); each command maps its parameters to its flags
(``{"grid_deg": "--grid-deg"}``) and :func:`flag_names` rewrites the error it passes on.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from speclight.errors import InputError


def cli_words(message: str, flags: dict[str, str]) -> str:
    """A core's message in the command line's words: ``flags`` maps Python parameter names
    to flags. Cores name a parameter as Python code would (``n_phases = 0 must be ...``,
    ``use method='slsqp'``, ``pass force=True``, or ```bin_s``` in prose):

    * ```name``` -> ``flag``; ``name=True`` -> ``flag``; ``name='v'`` and ``name=v`` ->
      ``flag v``; ``name=['a', 'b']`` -> ``flag a b``; ``name = `` -> ``flag = ``;
    * a name with an underscore (``min_period_s``) wherever it stands as a word; a plain word
      (``draws``) only in the forms above, so that the prose around it stays.
    """
    for name, flag in flags.items():
        n = re.escape(name)
        message = message.replace(f"`{name}`", flag)
        message = re.sub(rf"(?<![\w.-]){n}=True\b", flag, message)
        message = re.sub(rf"(?<![\w.-]){n}=\[([^\]]*)\]", _listed(flag), message)
        message = re.sub(rf"(?<![\w.-]){n}='([^']*)'", rf"{flag} \1", message)
        message = re.sub(rf"(?<![\w.-]){n}=(?=[^\s=])", f"{flag} ", message)
        tail = r"(?![\w-])" if "_" in name else r"(?= = )"
        message = re.sub(rf"(?<![\w.-]){n}{tail}", flag, message)
    return message


def _listed(flag: str) -> Callable[[re.Match[str]], str]:
    """``name=['a', 'b']`` -> ``flag a b`` (a list option given as its values)."""
    return lambda m: f"{flag} " + " ".join(v.strip().strip("'") for v in m.group(1).split(","))


@contextmanager
def flag_names(**flags: str) -> Iterator[None]:
    """Say the command-line flags where a plain-array core's error names its Python
    parameters (``n_phases = 0`` -> ``--phases = 0``; :func:`cli_words`): ``flags`` maps
    parameter names to flags; the error's field becomes the flag too."""
    try:
        yield
    except InputError as exc:
        message = cli_words(exc.message, flags)
        field = flags.get(str(exc.field), exc.field)
        if message == exc.message and field == exc.field:
            raise
        raise InputError(message, source=exc.source, field=field) from None
