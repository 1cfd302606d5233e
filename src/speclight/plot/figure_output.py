"""Figure files of the estimation commands, claimed and written like their main outputs.

A command that writes ``-o OUT`` and ``--plot FIG`` claims both before any work
(:class:`speclight.io.output.OutputClaim`: atomic, no overwrite without ``--force``, neither
may be an input, and the figure may not be the output); the figure is rendered in memory and
written through its claim.
"""

from __future__ import annotations

import io
import os
from collections.abc import Iterator, Mapping
from contextlib import ExitStack, contextmanager
from pathlib import Path
from typing import Any

from speclight.errors import InputError
from speclight.io.output import OutputClaim

#: File formats the estimation figures can be written in (by the file's suffix).
FIGURE_FORMATS = ("png", "pdf", "svg")
DPI = 120


def figure_format(path: str | os.PathLike[str], field: str = "--plot") -> str:
    """The format of a figure file from its suffix, checked before any work (matplotlib too)."""
    from speclight.engine_packages import require_engine

    suffix = Path(path).suffix.lower().lstrip(".")
    if suffix not in FIGURE_FORMATS:
        raise InputError(
            f"{os.fspath(path)}: unknown figure format '.{suffix}' (choices: "
            f"{', '.join('.' + f for f in FIGURE_FORMATS)})",
            field=field,
        )
    require_engine("matplotlib", field, "drawing figures")
    return suffix


class FigureClaim:
    """A claimed figure file: :meth:`write` renders a figure into it."""

    def __init__(self, claim: OutputClaim, fmt: str) -> None:
        self.claim = claim
        self.fmt = fmt

    def write(self, fig: Any) -> Path:
        """Render ``fig`` in memory and write it atomically."""
        buffer = io.BytesIO()
        fig.savefig(buffer, format=self.fmt, dpi=DPI)
        return self.claim.write(buffer.getvalue())


@contextmanager
def claim_outputs(
    output: str,
    plot: str | None,
    force: bool,
    inputs: Mapping[str, str | os.PathLike[str]],
) -> Iterator[tuple[OutputClaim, FigureClaim | None]]:
    """Claim ``output`` and, if given, the figure ``plot`` (see the module docstring).

    Raises
    ------
    InputError
        A bad or existing name (without ``force``), an input named as an output, the figure
        equal to the output, an unknown figure format or matplotlib missing.
    """
    fmt = figure_format(plot) if plot is not None else ""
    with ExitStack() as stack:
        claim = stack.enter_context(OutputClaim(output, force=force, inputs=inputs))
        figure = None
        if plot is not None:
            both = {**inputs, "output": output}
            try:
                fig_claim = stack.enter_context(OutputClaim(plot, force=force, inputs=both))
            except InputError as exc:  # the same checks as the output's, named for --plot
                raise InputError(exc.message, source=exc.source, field="--plot") from None
            figure = FigureClaim(fig_claim, fmt)
        yield claim, figure
