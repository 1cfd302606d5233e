"""Progress of long stages: one rich display on a terminal, nothing otherwise.

Every long stage of a run (orbit and geometry, rendering in both modes, the atmosphere, laser
ranging) reports through :func:`stage`, so that what a terminal shows is consistent and a
run in a script, a notebook cell without a terminal or a test prints nothing. A stage with a
known amount of work shows a bar (advance it by the units done); one without shows a
spinner with the stage's name and the time it has taken.

Examples
--------
>>> with stage("atmosphere (6S)", enabled=True) as advance:
...     advance(0)  # no terminal here: shows nothing
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import IO

Advance = Callable[[int], None]
#: A stage that took at least this long [s] leaves a closing line with its time (quicker
#: ones vanish with their display, so that a loop of short runs, e.g. a fit, stays quiet).
REPORT_AFTER_S = 1.0


def _noop(n: int) -> None:
    del n


def shown(enabled: bool, *, force: bool = False, file: IO[str] | None = None) -> bool:
    """Whether a stage prints: asked for, and standard error (or ``file``) is a terminal.

    ``force`` shows it on any stream (tests, or a caller that knows better).
    """
    if not enabled:
        return False
    if force:
        return True
    stream = file if file is not None else sys.stderr
    isatty = getattr(stream, "isatty", None)
    return bool(isatty is not None and isatty())


@contextmanager
def stage(
    label: str,
    total: int | None = None,
    *,
    enabled: bool = True,
    force: bool = False,
    file: IO[str] | None = None,
) -> Iterator[Advance]:
    """Show the progress of one stage while the ``with`` block runs.

    Parameters
    ----------
    label
        What the stage does, e.g. ``"rendering (path)"``; shown before the bar.
    total
        Units of work (epochs, batches) for a bar; None for a spinner with the elapsed time.
    enabled
        False: show nothing (the caller's ``progress`` switch).
    force
        Show even when the stream is not a terminal.
    file
        Stream to draw on (default standard error).

    Yields
    ------
    callable
        ``advance(n)``: n more units done (a no-op when nothing is shown).
    """
    if not shown(enabled, force=force, file=file):
        yield _noop
        return
    from rich.console import Console
    from rich.markup import escape
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        SpinnerColumn,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    console = Console(file=file if file is not None else sys.stderr, force_terminal=force or None)
    if total is None:
        columns = [SpinnerColumn(), TextColumn("{task.description}"), TimeElapsedColumn()]
    else:
        columns = [
            TextColumn("{task.description}"),
            BarColumn(),
            MofNCompleteColumn(),
            TimeElapsedColumn(),
            TimeRemainingColumn(),
        ]
    bar = Progress(*columns, console=console, transient=True)
    task = bar.add_task(label, total=total)
    with bar:
        yield lambda n: bar.advance(task, n)
    # a line per finished long stage, so a long run leaves the account of where its time went
    elapsed = bar.tasks[0].elapsed or 0.0
    if elapsed >= REPORT_AFTER_S:
        console.print(f"[green]done[/green] {escape(label)} ({elapsed:.1f} s)", highlight=False)
