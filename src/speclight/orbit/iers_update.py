"""``speclight update-data``: install a newer IERS ``finals2000A.all`` in the user data folder.

The table comes from the IERS Rapid Service (the address skyfield itself uses) or from a
file the user has (``--from``). It is checked before it replaces anything: it must be a
``finals2000A.all`` (fixed columns, days increasing, UT1-UTC values) holding the whole
history that the shipped one holds (from 1973), since skyfield takes the leap seconds and
Delta T from it; a ``finals.daily`` (the last 90 days only) is refused, and so is a table
cut short in the middle of a line (an interrupted download or copy). It is written
atomically into :func:`speclight.orbit.iers_files.installed_finals_path`, never into the
package folder, and runs then use it when it reaches further than the shipped one.

Nothing else in speclight fetches anything: this module is the only one that opens a URL,
and only when the command asks it to.
"""

from __future__ import annotations

import contextlib
import os
import secrets
import urllib.error
import urllib.request
from dataclasses import dataclass
from pathlib import Path

from speclight.errors import InputError, SpeclightError
from speclight.input_files import read_user_text
from speclight.io.output import create_new_file
from speclight.orbit.iers_files import (
    FINALS,
    FinalsCoverage,
    finals_coverage,
    finals_path,
    installed_finals_path,
    parse_coverage,
    shipped_data_dir,
    shipped_finals_path,
)
from speclight.orbit.timescale import reload_tables

#: Largest table accepted [bytes] (the full table is ~3.7 MB and grows ~70 kB a year).
MAX_TABLE_BYTES = 64 * 1024 * 1024


class DataUpdateError(SpeclightError):
    """The table could not be fetched or installed (network, file system)."""


@dataclass(frozen=True)
class UpdateResult:
    """What ``update-data`` installed and which table runs now use."""

    installed: Path
    coverage: FinalsCoverage
    in_use: Path
    source: str


def default_url() -> str:
    """The address skyfield downloads ``finals2000A.all`` from (the IERS Rapid Service)."""
    from skyfield.api import Loader

    # a Loader creates its folder: give it the (existing) skyfield-data one
    return str(Loader(shipped_data_dir(), verbose=False).build_url(FINALS))


def fetch(url: str, timeout_s: float = 60.0) -> bytes:
    """Download ``url`` (any scheme urllib knows: https, http, ftp, file).

    Raises
    ------
    DataUpdateError
        No network, a refused or failed request, a timeout, or a reply over
        :data:`MAX_TABLE_BYTES`.
    """
    try:
        with urllib.request.urlopen(url, timeout=timeout_s) as reply:
            data = bytes(reply.read(MAX_TABLE_BYTES + 1))
    except (urllib.error.URLError, OSError, ValueError) as exc:
        reason = getattr(exc, "reason", None) or exc
        raise DataUpdateError(
            f"cannot download {url} ({reason}); check the connection, or download the file "
            f"elsewhere and install it with `speclight update-data --from {FINALS}`"
        ) from exc
    if len(data) > MAX_TABLE_BYTES:
        raise DataUpdateError(f"{url} sent more than {MAX_TABLE_BYTES} bytes; not a {FINALS}")
    return data


def check_table(text: str, source: str) -> FinalsCoverage:
    """The coverage of ``text`` if it is a complete ``finals2000A.all``, else InputError.

    A table cut short (a download or a copy stopped) is refused: its last line has no line
    end and is shorter than the table's rows, and its last values may be cut (a UT1-UTC of
    ``0.05`` for ``0.0512345``).
    """
    _refuse_cut_line(text, source)
    coverage = parse_coverage(text)
    if coverage is None:
        raise InputError(
            f"not an IERS {FINALS} table (fixed columns: MJD in 8-15, UT1-UTC in 59-68, one "
            "row per day in increasing order); download it from the IERS Rapid Service, "
            f"{default_url()}",
            source=source,
        )
    shipped = finals_coverage(shipped_finals_path())
    if shipped is not None and coverage.first > shipped.first:
        raise InputError(
            f"the table starts on {coverage.first}, but leap seconds and Delta T need the "
            f"whole history from {shipped.first} on (a finals.daily holds only the last 90 "
            f"days); give the complete {FINALS}",
            source=source,
        )
    return coverage


def _refuse_cut_line(text: str, source: str) -> None:
    """Refuse a table whose last line has no line end and is shorter than the line before
    (the rows of a finals2000A.all have one length)."""
    if not text or text.endswith("\n"):
        return
    lines = text.split("\n")
    if len(lines) > 1 and len(lines[-1]) < len(lines[-2]):
        raise InputError(
            f"the table ends in the middle of line {len(lines)} ({len(lines[-1])} characters "
            f"and no line end, the row before has {len(lines[-2])}): it was cut short; "
            f"download the complete {FINALS} again",
            source=source,
        )


def install_table(text: str, source: str) -> UpdateResult:
    """Check ``text`` (:func:`check_table`) and install it atomically as the user's table.

    Raises
    ------
    InputError
        ``text`` is not a complete ``finals2000A.all``.
    DataUpdateError
        The user data folder cannot be created or written.
    """
    coverage = check_table(text, source)
    target = installed_finals_path()
    temp = target.with_name(f".{target.name}.{os.getpid()}-{secrets.token_hex(4)}.tmp")
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        fd = create_new_file(temp)
        with os.fdopen(fd, "w", encoding="ascii", errors="strict", newline="\n") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(temp, target)
    except (OSError, UnicodeEncodeError) as exc:
        raise DataUpdateError(f"cannot write {target}: {exc}; nothing was changed") from exc
    finally:
        with contextlib.suppress(OSError):
            temp.unlink()
    reload_tables()
    return UpdateResult(target, coverage, finals_path(), source)


def update_from_file(path: str | Path) -> UpdateResult:
    """Install the ``finals2000A.all`` at ``path`` (see :func:`install_table`)."""
    text = read_user_text(path, "--from", what=f"IERS {FINALS}", max_bytes=MAX_TABLE_BYTES)
    return install_table(text, str(path))


def update_from_url(url: str | None = None, timeout_s: float = 60.0) -> UpdateResult:
    """Download ``finals2000A.all`` (from :func:`default_url` unless ``url`` is given) and
    install it (see :func:`install_table`)."""
    address = url or default_url()
    data = fetch(address, timeout_s)
    try:
        text = data.decode("ascii")
    except UnicodeDecodeError as exc:
        raise InputError(f"not an IERS {FINALS} table (not ASCII text)", source=address) from exc
    return install_table(text.replace("\r\n", "\n"), address)
