"""Hold back interrupting signals while an output is serialised or moved into place.

h5py runs Python callbacks (weakref finalisers) while HDF5 writes. A ``KeyboardInterrupt``
raised by a signal handler inside one of them is printed as "Exception ignored in ..." and
dropped, so a Ctrl-C during ``to_netcdf`` was lost: the run went on, printed a traceback and
exited 0. Inside :func:`hold_signals`, SIGINT, SIGTERM and SIGHUP are only recorded; when the
block ends, the handlers in place before are restored and the first recorded signal is sent
again, so that it acts where its exception cannot be lost. Loops inside the block poll
:attr:`HeldSignals.pending` to stop early.
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType
from typing import Any

#: The signals that end a run and are held back (SIGKILL cannot be caught).
INTERRUPTING_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


class HeldSignals:
    """The signal received while held (``pending``), None if none."""

    def __init__(self) -> None:
        self.pending: int | None = None

    def record(self, signum: int, frame: FrameType | None) -> None:
        """Signal handler: remember the first signal."""
        if self.pending is None:
            self.pending = signum


@contextmanager
def hold_signals() -> Iterator[HeldSignals]:
    """Record SIGINT, SIGTERM and SIGHUP in the block, and send the first one again after it.

    A signal that is ignored stays ignored (``nohup`` keeps working). Outside the main
    thread, where Python cannot set handlers, the block runs without holding anything.

    Yields
    ------
    HeldSignals
        Its ``pending`` attribute is the signal received so far, None if none.
    """
    held = HeldSignals()
    previous: dict[signal.Signals, Any] = {}
    if threading.current_thread() is threading.main_thread():
        for signum in INTERRUPTING_SIGNALS:
            current = signal.getsignal(signum)
            if current is not signal.SIG_IGN and current is not None:
                previous[signum] = signal.signal(signum, held.record)
    try:
        yield held
    finally:
        for held_signum, handler in previous.items():
            signal.signal(held_signum, handler)
        if held.pending is not None:
            signal.raise_signal(held.pending)
