"""Figure files of the estimation commands, claimed and written like their main outputs.

A command that writes ``-o OUT`` and ``--plot FIG`` claims both before any work
(:class:`speclight.io.output.OutputClaim`: atomic, no overwrite without ``--force``, neither
may be an input, and the figure may not be the output); :func:`write_outputs` renders the
figure in memory and writes both files or neither (a Ctrl-C while the figure draws leaves no
output that would make the rerun need ``--force``).
"""

from __future__ import annotations

import contextlib
import io
import os
from collections.abc import Callable, Iterator, Mapping
from contextlib import ExitStack, contextmanager
from pathlib import Path
from typing import Any

from speclight.errors import InputError
from speclight.io.held_signals import hold_signals
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
    """A claimed figure file: :meth:`render` draws a figure into memory, :meth:`write`
    writes it."""

    def __init__(self, claim: OutputClaim, fmt: str) -> None:
        self.claim = claim
        self.fmt = fmt

    def render(self, fig: Any) -> bytes:
        """The file's bytes: ``fig`` drawn in memory."""
        buffer = io.BytesIO()
        fig.savefig(buffer, format=self.fmt, dpi=DPI)
        return buffer.getvalue()

    def write(self, fig: Any) -> Path:
        """Render ``fig`` in memory and write it atomically."""
        return self.claim.write(self.render(fig))


def write_outputs(
    claim: OutputClaim,
    data: bytes | bytearray | memoryview,
    figure: FigureClaim | None,
    build_figure: Callable[[], Any],
) -> None:
    """Write an output and its figure (if one is claimed) together, or neither.

    The figure is built (``build_figure()``) and drawn in memory before anything is written,
    so a signal or an error while it draws leaves no file behind and the same command can
    simply be run again. Signals are then held while the two files are written (one that
    comes in between acts after both are complete); a signal or an error while one of them
    is written removes the output again.

    Raises
    ------
    OutputWriteError
        A file could not be written (full disk...); neither is left.
    """
    image = figure.render(build_figure()) if figure is not None else None
    with hold_signals():
        claim.write(data)
        if figure is None or image is None:
            return
        try:
            figure.claim.write(image)
        except BaseException:
            with contextlib.suppress(OSError):
                claim.path.unlink()
            raise


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
