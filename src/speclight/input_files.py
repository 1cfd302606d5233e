"""Safe reading of the files a user names (scenario, orbit files, tables, meshes, materials).

:func:`check_user_file`, :func:`read_user_bytes` and :func:`read_user_text` turn every way a
named file can be unusable into an :class:`~speclight.errors.InputError` that names the file
and the scenario field: a path that does not exist, a folder, anything that is not a regular
file (a FIFO or a device such as ``/dev/zero``: refused from ``os.stat`` before opening, so
nothing blocks or reads forever), a loop of symbolic links, a file this user may not read,
a file above a size limit, and (for text) bytes that are not UTF-8 (the message says where
the first bad byte is). NetCDF datasets are read by :mod:`speclight.io.user_dataset`
after the same checks.
"""

from __future__ import annotations

import codecs
import errno
import os
import stat
from collections.abc import Callable
from pathlib import Path

from speclight.errors import InputError

#: Largest text input file read [bytes]. A CPF or CSV ephemeris at a 1 s step for a week
#: is about 50 MB; anything larger is refused rather than read into memory.
MAX_TEXT_BYTES = 256 * 1024 * 1024

_KINDS = (
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)
_UTF16_BOMS = (codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)


def check_user_file(
    path: str | Path,
    field: str | None = None,
    *,
    what: str = "file",
    max_bytes: int | None = MAX_TEXT_BYTES,
) -> os.stat_result:
    """Refuse a path that is not a readable regular file, before anything opens it.

    Parameters
    ----------
    path
        The file (``~`` is expanded).
    field
        Scenario field or command-line argument that names the file, for the message.
    what
        What the file is, for the message (e.g. ``"TLE file"``).
    max_bytes
        Size limit [bytes], or None for none (a NetCDF dataset is read a variable at a time).

    Returns
    -------
    os.stat_result
        The file's status.

    Raises
    ------
    InputError
        Missing path, a folder, a symbolic-link loop, not a regular file (a FIFO or device:
        refused from ``os.stat`` before opening, so nothing blocks), an invalid path, larger
        than ``max_bytes``, or not readable (permission denied: found by opening it).
    """
    path = Path(path).expanduser()
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise _refusal(path, field, what, "no such file: it does not exist") from None
    except NotADirectoryError:
        raise _refusal(
            path,
            field,
            what,
            "no such file: it does not exist (a part of the path is a file, not a folder)",
        ) from None
    except OSError as exc:
        raise _refusal(path, field, what, _os_problem(exc)) from None
    except ValueError:  # a NUL character in the path
        raise _refusal(path, field, what, "not a valid path (it holds a NUL character)") from None
    if stat.S_ISDIR(st.st_mode):
        raise _refusal(path, field, what, "it is a folder; give the path of a file in it")
    if not stat.S_ISREG(st.st_mode):
        kind = next((name for test, name in _KINDS if test(st.st_mode)), "not a regular file")
        raise _refusal(
            path, field, what, f"it is {kind}, not a regular file; give the path of a file"
        )
    if max_bytes is not None and st.st_size > max_bytes:
        problem = f"it is {_size(st.st_size)}, above the limit of {_size(max_bytes)}"
        raise _refusal(path, field, what, problem)
    try:
        with open(path, "rb"):
            pass
    except OSError as exc:
        raise _refusal(path, field, what, _os_problem(exc)) from None
    return st


def read_user_bytes(
    path: str | Path,
    field: str | None = None,
    *,
    what: str = "file",
    max_bytes: int = MAX_TEXT_BYTES,
) -> bytes:
    """The bytes of a user's file (tables, meshes, material files), refusing anything that is
    not a readable regular file with a clear error.

    Parameters are those of :func:`check_user_file`.

    Raises
    ------
    InputError
        As :func:`check_user_file`, and a file that grew above ``max_bytes`` or failed to
        read.
    """
    path = Path(path).expanduser()
    check_user_file(path, field, what=what, max_bytes=max_bytes)
    try:
        with open(path, "rb") as f:
            data = f.read(max_bytes + 1)
    except OSError as exc:
        raise _refusal(path, field, what, _os_problem(exc)) from None
    if len(data) > max_bytes:  # grew since os.stat
        raise _refusal(path, field, what, f"it is larger than the limit of {_size(max_bytes)}")
    return data


def _refusal(path: Path, field: str | None, what: str, problem: str) -> InputError:
    return InputError(f"cannot read {what}: {problem}", source=str(path), field=field)


def _os_problem(exc: OSError) -> str:
    """The reason of an ``OSError`` in words, with what to do where there is something."""
    if exc.errno == errno.ELOOP:
        return "a loop of symbolic links (a link that points back to itself); fix the link"
    if isinstance(exc, PermissionError):
        return "permission denied: this user may not read it (see its mode, ls -l)"
    return exc.strerror or str(exc)


def read_user_text(
    path: str | Path,
    field: str | None = None,
    *,
    what: str = "file",
    max_bytes: int = MAX_TEXT_BYTES,
) -> str:
    """Read a user's UTF-8 text file, refusing anything else with a clear error.

    Parameters are those of :func:`read_user_bytes`.

    Returns
    -------
    str
        The text, a UTF-8 byte-order mark removed and line ends turned into ``"\\n"``
        (as Python's text mode does).

    Raises
    ------
    InputError
        As :func:`read_user_bytes`, and if the bytes are not UTF-8 text (binary, UTF-16,
        Latin-1...): the message says where the first bad byte is.
    """
    data = read_user_bytes(path, field, what=what, max_bytes=max_bytes)
    source = Path(path).expanduser()

    def refuse(problem: str) -> InputError:
        return _refusal(source, field, what, problem)

    return _decode(data, refuse).replace("\r\n", "\n").replace("\r", "\n")


def _decode(data: bytes, refuse: Callable[[str], InputError]) -> str:
    """UTF-8 text of ``data``; ``refuse(problem)`` builds the error otherwise."""
    save = "save it as UTF-8"
    if data.startswith(_UTF16_BOMS):
        raise refuse(f"it is UTF-16 text (byte-order mark {data[:2].hex(' ')}); {save}")
    nul = data.find(b"\x00")
    try:
        text = data.decode("utf-8")  # not utf-8-sig: its error offsets skip the mark
    except UnicodeDecodeError as exc:
        if nul < 0 or exc.start < nul:  # report the first bad byte
            bad = data[exc.start : exc.start + 1].hex()
            raise refuse(
                f"byte 0x{bad} at {_where(data, exc.start)} is not UTF-8: the file is binary "
                f"or in another encoding (Latin-1, Windows-1252...); {save}"
            ) from None
    if nul >= 0:
        raise refuse(
            f"a NUL byte at {_where(data, nul)}: the file is binary or not UTF-8 text "
            f"(UTF-16 without a byte-order mark?); {save}"
        )
    return text.removeprefix("\ufeff")


def _where(data: bytes, offset: int) -> str:
    line = data.count(b"\n", 0, offset) + 1
    column = offset - (data.rfind(b"\n", 0, offset) + 1) + 1
    return f"line {line}, column {column} (byte {offset})"


def _size(n_bytes: int) -> str:
    return f"{n_bytes / 2**20:.1f} MiB" if n_bytes >= 2**20 else f"{n_bytes} bytes"
