"""What every resumable Zarr store of speclight (reflectivity maps, sweeps) needs from its disk.

* :func:`store_lock`: one writer at a time (a lock file beside the store);
* :func:`store_writes`: a write that fails (a full disk, a quota, an I/O error) ends the run
  with :class:`~speclight.io.output.OutputWriteError` (exit 1, one line), and the store keeps
  what was written: rerunning the same command resumes it;
* :func:`check_free_space`: a store that cannot fit on its disk is refused before any work;
* :func:`readable`: whether a region that the store says is done can be read back (a chunk
  file cut short, or deleted, is not), so that a resumed run renders it again.

Zarr writes each chunk file whole (to a temporary name, then renamed), so a failed write
leaves the chunks before it intact and the chunk it was writing absent.
"""

from __future__ import annotations

import errno
import fcntl
import os
import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from speclight.errors import InputError
from speclight.io.output import OutputWriteError, lock_path

FIELD = "--output"
#: Room left on the disk beyond a store's estimated size [bytes]: its metadata, the
#: temporary file of the chunk being written, and the rest of the system.
FREE_SPACE_MARGIN_BYTES = 64 * 1024**2


@contextmanager
def store_lock(path: Path) -> Iterator[None]:
    """Hold ``.NAME.speclight.lock`` beside the store (one writer at a time).

    The lock is taken on the store's real path (a symbolic link to it, or to its folder,
    takes the same lock). A run that finds the lock held stops at once and leaves the lock
    file alone; the holder removes it before releasing it, and a run that locked a file
    removed in between tries again, so two runs never both hold the store.
    """
    lock = lock_path(path.resolve())
    while True:
        try:
            fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o666)
        except OSError as exc:
            raise _write_error(path, exc) from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise InputError(
                f"another speclight run is writing {path}; wait for it to end", field=FIELD
            ) from None
        try:
            if os.stat(lock).st_ino == os.fstat(fd).st_ino:
                break  # the file at the lock's path is the one locked
        except FileNotFoundError:
            pass
        os.close(fd)  # the holder before us removed it: lock the new one
    try:
        yield
    finally:
        lock.unlink(missing_ok=True)  # before releasing: no one can lock a removed file
        os.close(fd)


def _write_error(path: Path, exc: OSError) -> OutputWriteError:
    reason = exc.strerror or str(exc)
    full = exc.errno in (errno.ENOSPC, errno.EDQUOT)
    hint = "free some space" if full else "fix the cause"
    return OutputWriteError(
        f"cannot write {path}: {reason}; the store keeps what was written: {hint} and rerun "
        "the same command to resume it"
    )


@contextmanager
def store_writes(path: Path) -> Iterator[None]:
    """Turn an ``OSError`` of the writes in the block into one :class:`OutputWriteError`."""
    try:
        yield
    except OutputWriteError:
        raise
    except OSError as exc:
        raise _write_error(path, exc) from None


def check_free_space(path: Path, needed_bytes: int, what: str, field: str) -> None:
    """Refuse a store whose data (``needed_bytes``, uncompressed: an upper bound) would not
    fit on the disk of ``path``'s folder, before any work.

    ``what`` describes the size (shown in the message); ``field`` is the option to reduce.
    """
    try:
        free = shutil.disk_usage(path.parent if not path.exists() else path).free
    except OSError:
        return  # no answer: the writes report a full disk themselves
    if needed_bytes + FREE_SPACE_MARGIN_BYTES <= free:
        return
    raise InputError(
        f"{what} needs up to {_size(needed_bytes)} on disk, more than the "
        f"{_size(free)} free where {path} is (with {_size(FREE_SPACE_MARGIN_BYTES)} to "
        f"spare); reduce {field}, free some space or write the store elsewhere",
        field=field,
    )


def _size(n: float) -> str:
    return f"{n / 1024**3:.3g} GiB" if n >= 1024**3 else f"{n / 1024**2:.3g} MiB"


def readable(arrays: list[Any], region: slice, complete: str | None = None) -> bool:
    """Whether ``arrays[k][region]`` all read back, and the array named ``complete`` (one
    that a finished region always fills, such as a map's intensity) holds no fill value
    (NaN) there: a chunk file cut short fails to decode, a deleted one reads as NaN."""
    for arr in arrays:
        try:
            values = arr[region]
        except Exception:  # a damaged chunk: any decoding error of Zarr or its codecs
            return False
        if complete is not None and arr.basename == complete and np.isnan(values).any():
            return False
    return True
