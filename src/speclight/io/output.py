"""Claim an output file before the work starts, and write it atomically.

How a run writes ``out.nc`` (outputs are never overwritten without ``force``, never
half-written, and an interrupted run leaves nothing behind):

1. :func:`check_output_path` refuses, before any work, an empty name, a folder, a missing
   or unwritable folder, an input file of the run (in any spelling of its path), and an
   existing file unless ``force`` is set.
2. :class:`OutputClaim` takes the lock ``.out.nc.speclight.lock`` beside the output: an
   exclusive ``flock`` held for the whole run, with the PID inside for the message that a
   second run to the same output gets. The kernel releases the lock when the process ends,
   however it ends (SIGKILL included), so the lock of a killed run is simply taken over:
   no guessing from PIDs, which are reused.
3. Holding the lock, the claim removes what killed runs left in the folder: temporary files
   ``.NAME.speclight-PID-XXXXXXXX.tmp`` of outputs whose lock nobody holds, and such locks.
4. :meth:`OutputClaim.write` writes the bytes to a temporary file created by
   :func:`create_new_file` (mode 0666 less the umask, as any new file) with ordinary file
   I/O, which fails cleanly on a full disk, flushes it to disk and moves it into place: with
   ``os.link``, which fails if the output appeared meanwhile, unless ``force`` allows
   replacing it. On any error or signal the temporary file is removed.

The lock needs POSIX ``flock`` (Linux, macOS; NFS through the kernel's lock emulation).
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import os
import re
import secrets
from collections.abc import Mapping
from pathlib import Path
from types import TracebackType

from speclight.errors import InputError, SpeclightError
from speclight.io.held_signals import HeldSignals, hold_signals

FIELD = "--output"
_LOCK = re.compile(r"^\.(?P<name>.+)\.speclight\.lock$")
_TEMP = re.compile(r"^\.(?P<name>.+)\.speclight-\d+-[0-9a-f]+\.tmp$")
_CHUNK_BYTES = 1 << 20
#: ``os.link`` errors of file systems without hard links: fall back to ``os.replace``.
_NO_HARD_LINKS = {errno.EPERM, errno.ENOTSUP, errno.EOPNOTSUPP, errno.EMLINK, errno.ENOSYS}
#: Errors of the disk rather than of the folder the user chose.
_DISK_ERRORS = {errno.ENOSPC, errno.EDQUOT, errno.EIO}


class OutputWriteError(SpeclightError):
    """The output could not be written (full disk, I/O error...); nothing was left behind."""


def create_new_file(path: str | os.PathLike[str]) -> int:
    """Create ``path`` for writing (it must not exist yet) and return its descriptor.

    The file gets the mode any new file gets, 0666 less the process's umask. Every output
    file of speclight is written to such a file and then moved into place, which keeps the
    mode: a temporary file from :mod:`tempfile` would make every output 0600, readable by its
    owner only.

    Raises
    ------
    FileExistsError
        ``path`` exists.
    OSError
        The file system refused.
    """
    return os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, 0o666)


def lock_path(output: Path) -> Path:
    """The lock file of ``output``: ``.NAME.speclight.lock`` beside it."""
    return output.with_name(f".{output.name}.speclight.lock")


def check_output_path(
    output: str | os.PathLike[str],
    force: bool = False,
    inputs: Mapping[str, str | os.PathLike[str]] | None = None,
) -> Path:
    """Refuse an output name that cannot or must not be written, before any work.

    Parameters
    ----------
    output
        The output file as the user gave it.
    force
        An existing (regular) file may be replaced.
    inputs
        Files the run reads, by role (e.g. ``{"scenario file": path}``): the output must be
        none of them, whatever the spelling of the path (links included).

    Returns
    -------
    Path
        The output path.

    Raises
    ------
    InputError
        Naming ``--output``, the value and what is accepted.
    """
    text = os.fspath(output)
    if not text.strip():
        raise InputError("the file name is empty; give one such as out.nc", field=FIELD)
    path = Path(text)
    if text.endswith(("/", os.sep)) or path.name in ("", ".", "..") or path.is_dir():
        raise InputError(
            f"{text} names a folder; give a file name such as {path / 'out.nc'}", field=FIELD
        )
    folder = path.parent
    if not folder.exists():
        raise InputError(f"folder {folder} of {text} does not exist; create it first", field=FIELD)
    if not folder.is_dir():
        raise InputError(f"{folder} in {text} is a file, not a folder", field=FIELD)
    for role, other in (inputs or {}).items():
        if _same_file(path, Path(other)):
            raise InputError(
                f"{text} is the {role} {other}; choose another name, it would be overwritten",
                field=FIELD,
            )
    if path.exists() or path.is_symlink():
        if not force:
            raise InputError(
                f"{text} exists; choose another name or pass --force to overwrite it", field=FIELD
            )
        if not path.is_file():
            raise InputError(
                f"{text} exists and is not a regular file; --force replaces only files",
                field=FIELD,
            )
    if not os.access(folder, os.W_OK | os.X_OK):
        raise InputError(
            f"cannot write in folder {folder} (permission denied); choose another folder",
            field=FIELD,
        )
    return path


def _same_file(a: Path, b: Path) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:  # one of them does not exist (yet), or is a loop of symbolic links
        return os.path.realpath(a) == os.path.realpath(b)  # never raises, loops included


class OutputClaim:
    """Exclusive right to write one output file, from before the work until it is written.

    Use it as a context manager: entering checks the name (:func:`check_output_path`),
    takes the lock and removes what killed runs left; leaving removes the lock (and the
    temporary file, should a write have been cut short).

    Parameters
    ----------
    output
        The output file.
    force
        Replace an existing file.
    inputs
        Files the run reads, by role: the output must be none of them.

    Raises
    ------
    InputError
        On entering: a bad name (see :func:`check_output_path`), an unwritable folder, or
        another run holding the lock (its PID is in the message).
    """

    def __init__(
        self,
        output: str | os.PathLike[str],
        *,
        force: bool = False,
        inputs: Mapping[str, str | os.PathLike[str]] | None = None,
    ) -> None:
        self.output = output
        self.force = force
        self.inputs = inputs
        self.path = Path(os.fspath(output))
        self._lock_fd: int | None = None

    def __enter__(self) -> OutputClaim:
        self.path = check_output_path(self.output, self.force, self.inputs)
        lock = lock_path(self.path)
        try:
            # held: a signal between creating the lock and keeping its descriptor would
            # leave the lock behind (the signal acts when the block ends, and is caught below)
            with hold_signals():
                fd = _take_lock(lock)
                self._lock_fd = fd
        except OSError as exc:
            raise self._folder_error(exc) from exc
        except BaseException:
            self._release()
            raise
        if fd is None:
            pid = _lock_owner(lock)
            who = f"another speclight run (PID {pid})" if pid else "another speclight run"
            raise InputError(
                f"{self.output} is being written by {who}; wait for it to finish or choose "
                "another name",
                field=FIELD,
            )
        try:
            try:
                os.ftruncate(fd, 0)
                os.write(fd, f"{os.getpid()}\n".encode())
            except OSError as exc:  # a full disk or quota: the empty lock file was created
                raise self._folder_error(exc) from exc
            check_output_path(self.output, self.force, self.inputs)  # a run may just have ended
            _sweep(self.path.parent, own=self.path.name)
        except BaseException:
            self._release()
            raise
        return self

    def _folder_error(self, exc: OSError) -> InputError | OutputWriteError:
        """Why the lock cannot be written: the disk (a full disk, a quota, an I/O error: exit
        1, as when the output cannot be written) or the folder (permission...: exit 2)."""
        if exc.errno in _DISK_ERRORS:
            return OutputWriteError(
                f"cannot write {self.output}: {exc.strerror or exc} (its lock file in "
                f"{self.path.parent}); nothing was written"
            )
        return InputError(
            f"cannot write in folder {self.path.parent} ({exc.strerror}); choose another folder",
            field=FIELD,
        )

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self._release()

    def _release(self) -> None:
        if self._lock_fd is None:
            return
        with hold_signals():  # a second Ctrl-C must not leave the lock behind
            with contextlib.suppress(OSError):
                lock_path(self.path).unlink()
            os.close(self._lock_fd)
            self._lock_fd = None

    def write(self, data: bytes | bytearray | memoryview) -> Path:
        """Write ``data`` to the output atomically; returns the output path.

        Raises
        ------
        OutputWriteError
            The file system refused (full disk, quota, I/O error), or a file of that name
            appeared during the run and ``force`` is not set; nothing was written.
        KeyboardInterrupt
            Or whatever the handler of a signal received during the write raises, after the
            temporary file is removed.
        """
        if self._lock_fd is None:
            raise RuntimeError("OutputClaim.write outside its `with` block")
        view = memoryview(data).cast("B")
        token = secrets.token_hex(4)
        temp = self.path.with_name(f".{self.path.name}.speclight-{os.getpid()}-{token}.tmp")
        with hold_signals() as held:
            try:
                fd = create_new_file(temp)
                try:
                    _write_all(fd, view, held)
                finally:
                    os.close(fd)
                if held.pending is None:
                    self._move_into_place(temp)
            except OSError as exc:
                raise OutputWriteError(
                    f"cannot write {self.output}: {exc.strerror or exc}; nothing was written"
                ) from exc
            finally:
                with contextlib.suppress(OSError):
                    temp.unlink()
        if held.pending is not None:  # its handler did not end the run
            raise OutputWriteError(f"cannot write {self.output}: interrupted by a signal")
        return self.path

    def _move_into_place(self, temp: Path) -> None:
        if not self.force:
            try:
                os.link(temp, self.path)  # atomic, and never replaces a file
                _sync_folder(self.path.parent)
                return
            except FileExistsError as exc:
                raise OutputWriteError(
                    f"cannot write {self.output}: a file of that name appeared during the run "
                    "(not from speclight); it was left as it is and the result was not written"
                ) from exc
            except OSError as exc:
                if exc.errno not in _NO_HARD_LINKS:
                    raise
            if self.path.exists():
                raise OutputWriteError(
                    f"cannot write {self.output}: a file of that name appeared during the run"
                )
        os.replace(temp, self.path)
        _sync_folder(self.path.parent)


def _write_all(fd: int, view: memoryview, held: HeldSignals) -> None:
    """Write all of ``view`` to ``fd`` and flush it to disk, unless a signal comes first."""
    done = 0
    while done < len(view) and held.pending is None:
        done += os.write(fd, view[done : done + _CHUNK_BYTES])
    if held.pending is None:
        os.fsync(fd)


def _sync_folder(folder: Path) -> None:
    with contextlib.suppress(OSError):  # not every file system can sync a folder
        fd = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def _take_lock(lock: Path) -> int | None:
    """Open and ``flock`` ``lock``: its descriptor, or None if another process holds it.

    The lock is the one on the file that is at ``lock`` now: a process that removed it
    while this one waited would otherwise leave two holders.
    """
    while True:
        fd = os.open(lock, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o666)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            return None
        except BaseException:
            os.close(fd)
            raise
        try:
            here = os.stat(lock)
            mine = os.fstat(fd)
            if (here.st_dev, here.st_ino) == (mine.st_dev, mine.st_ino):
                return fd
        except FileNotFoundError:
            pass
        os.close(fd)


def _lock_owner(lock: Path) -> int | None:
    """The PID written in a lock file, None if unreadable (being written just now)."""
    try:
        return int(lock.read_text().strip())
    except (OSError, ValueError):
        return None


def _sweep(folder: Path, own: str) -> None:
    """Remove temporary files and locks that runs killed earlier left in ``folder``.

    A temporary file of an output is written only by the holder of that output's lock, and
    removed before the lock, so the files listed before taking a free lock are left-overs.
    Files this user may not remove are left alone.
    """
    try:
        entries = os.listdir(folder)
    except OSError:
        return
    temps: dict[str, list[str]] = {}
    for entry in entries:
        if match := _TEMP.match(entry) or _LOCK.match(entry):
            files = temps.setdefault(match["name"], [])
            if entry.endswith(".tmp"):
                files.append(entry)
    for name, files in temps.items():
        lock = folder / f".{name}.speclight.lock"
        fd = None
        if name != own:
            try:
                fd = _take_lock(lock)
            except OSError:
                continue
            if fd is None:
                continue  # a live run
        for entry in files:
            with contextlib.suppress(OSError):
                (folder / entry).unlink()
        if fd is not None:
            with contextlib.suppress(OSError):
                lock.unlink()
            os.close(fd)
