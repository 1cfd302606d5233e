"""How every command runs: its errors as exit codes and one line, signals as the end of the run.

Exit codes: 0 success, 2 bad input (the message names the file, the field and what is
accepted), 1 internal error or an output the file system refused (full disk), 128 + N when
ended by signal N: 130 for Ctrl-C (SIGINT), 143 for SIGTERM, 129 for SIGHUP. An interrupted
run removes its temporary file and its output lock; one killed by SIGKILL leaves them to be
removed by the next run writing to the same folder (see :mod:`speclight.io.output`).
"""

from __future__ import annotations

import signal
import sys
import threading
import traceback
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from types import FrameType
from typing import Any, NoReturn

import typer

from speclight.errors import InputError
from speclight.io.held_signals import INTERRUPTING_SIGNALS
from speclight.io.output import OutputWriteError


class Terminated(BaseException):
    """SIGTERM or SIGHUP, raised like ``KeyboardInterrupt`` (which ``except Exception`` skips).

    Parameters
    ----------
    signum
        The signal received.
    """

    def __init__(self, signum: int) -> None:
        self.signum = signum
        super().__init__(signal.Signals(signum).name)


#: Signals received during this command (a library may drop the exception of one).
_received: list[int] = []


def _on_signal(signum: int, frame: FrameType | None) -> None:
    _received.append(signum)
    if signum == signal.SIGINT:
        raise KeyboardInterrupt
    raise Terminated(signum)


def raise_if_signalled() -> None:
    """Raise for a signal whose exception was dropped (printed as "Exception ignored")."""
    if _received:
        _on_signal(_received[0], None)


def _quiet_unraisable(unraisable: Any) -> None:
    if not isinstance(unraisable.exc_value, (KeyboardInterrupt, Terminated)):
        sys.__unraisablehook__(unraisable)


@contextmanager
def _signals_end_the_run() -> Iterator[None]:
    """SIGINT, SIGTERM and SIGHUP raise in the block; ignored ones stay ignored (nohup)."""
    _received.clear()
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {}
    for signum in INTERRUPTING_SIGNALS:
        if signal.getsignal(signum) in (signal.SIG_DFL, signal.default_int_handler):
            previous[signum] = signal.signal(signum, _on_signal)
    hook, sys.unraisablehook = sys.unraisablehook, _quiet_unraisable
    try:
        yield
    finally:
        sys.unraisablehook = hook
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def fail(message: str, code: int) -> NoReturn:
    """Print ``error: message`` on stderr and exit with ``code``."""
    typer.echo(f"error: {message}", err=True)
    raise typer.Exit(code)


def guarded(func: Callable[[], Any]) -> Any:
    """Run a command's body: its errors and signals become one line and an exit code."""
    try:
        with _signals_end_the_run():
            result = func()
            raise_if_signalled()
            return result
    except InputError as exc:
        fail(str(exc), 2)
    except OutputWriteError as exc:
        fail(str(exc), 1)
    except KeyboardInterrupt:
        fail("interrupted", 128 + signal.SIGINT)
    except Terminated as exc:
        fail(f"terminated by {exc}", 128 + exc.signum)
    except typer.Exit:
        raise
    except Exception:  # an internal error: say so, with the traceback for a bug report
        traceback.print_exc()
        fail("internal error (please report it with the traceback above)", 1)
