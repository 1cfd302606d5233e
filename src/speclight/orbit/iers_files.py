"""Which Earth-orientation and leap-second table speclight uses, and how far it reaches.

skyfield builds UTC -> TT (leap seconds, from the steps of UT1-UTC), UT1 and polar motion
from the IERS Rapid Service file ``finals2000A.all`` (IERS Conventions 2010, IERS Technical
Note 36, ch. 5; format: the ``readme.finals2000A`` of the IERS Rapid Service/Prediction
Centre). Two copies can exist:

* the one shipped in the ``skyfield-data`` package (fixed at its release);
* one that ``speclight update-data`` installed in the user data folder
  (:func:`user_data_dir`), never in the package folder.

:func:`finals_path` picks the installed one when it reaches further than the shipped one.
Nothing here touches the network.
"""

from __future__ import annotations

import functools
import os
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

FINALS = "finals2000A.all"
#: Sub-folder of the user data folder that holds the updated IERS table.
IERS_FOLDER = "iers"


def user_data_dir() -> Path:
    """User data folder: ``$SPECLIGHT_DATA_DIR``, else ``$XDG_DATA_HOME/speclight``, else
    ``~/.local/share/speclight`` (the XDG base-directory default)."""
    env = os.environ.get("SPECLIGHT_DATA_DIR")
    if env:
        return Path(env).expanduser()
    xdg = os.environ.get("XDG_DATA_HOME")
    base = Path(xdg).expanduser() if xdg else Path.home() / ".local" / "share"
    return base / "speclight"


def installed_finals_path() -> Path:
    """Where ``speclight update-data`` puts ``finals2000A.all`` (it may not exist)."""
    return user_data_dir() / IERS_FOLDER / FINALS


@functools.cache
def shipped_data_dir() -> str:
    """The ``skyfield-data`` folder (``finals2000A.all``, ``de421.bsp``)."""
    with warnings.catch_warnings():
        # skyfield-data warns once its table's prediction horizon has passed; speclight says
        # so itself, for the epochs of a run (speclight.orbit.staleness).
        warnings.simplefilter("ignore", RuntimeWarning)
        import skyfield_data

        return str(skyfield_data.get_skyfield_data_path())


def shipped_finals_path() -> Path:
    """The ``finals2000A.all`` shipped in ``skyfield-data``."""
    return Path(shipped_data_dir()) / FINALS


@dataclass(frozen=True)
class FinalsCoverage:
    """How far a ``finals2000A.all`` reaches (UTC dates, ``datetime64[D]``).

    Attributes
    ----------
    first
        First day with UT1-UTC.
    measured_until
        Last day whose UT1-UTC is from the IERS final/rapid solutions (flag ``I``).
    predicted_until
        Last day with any UT1-UTC (predictions, flag ``P``): beyond it skyfield
        extrapolates UT1 and knows of no further leap second.
    """

    first: np.datetime64
    measured_until: np.datetime64
    predicted_until: np.datetime64


_MJD0 = np.datetime64("1858-11-17", "D")


def _coverage_of_lines(lines: list[str]) -> FinalsCoverage | None:
    days = _table_days(lines)
    if not days:
        return None
    first, last = days[0][0], days[-1][0]
    measured = next((mjd for mjd, flag in reversed(days) if flag == "I"), None)
    day = np.timedelta64(1, "D")
    return FinalsCoverage(
        first=_MJD0 + first * day,
        measured_until=_MJD0 + (measured if measured is not None else first) * day,
        predicted_until=_MJD0 + last * day,
    )


def _table_days(lines: list[str]) -> list[tuple[int, str]] | None:
    """(MJD, UT1 flag) of every row with UT1-UTC; None for an unreadable value or days that
    do not increase."""
    days: list[tuple[int, str]] = []
    for line in lines:
        # columns (1-based) 8-15 MJD, 17 polar-motion flag, 58 UT1 flag, 59-68 UT1-UTC
        if len(line) < 68 or not line[7:15].strip() or not line[58:68].strip():
            continue
        try:
            mjd = int(float(line[7:15]))
            float(line[58:68])
        except ValueError:
            return None
        if days and mjd <= days[-1][0]:
            return None  # days must increase
        days.append((mjd, line[57]))
    return days


def parse_coverage(text: str) -> FinalsCoverage | None:
    """Coverage of the text of a ``finals2000A.all``; None if it is not one (no row with
    UT1-UTC, an unreadable value, or days that do not increase)."""
    return _coverage_of_lines(text.splitlines())


@functools.cache
def _coverage_cached(path: str, mtime_ns: int, size: int) -> FinalsCoverage | None:
    try:
        with open(path, encoding="ascii", errors="replace") as f:
            return _coverage_of_lines(f.read().splitlines())
    except OSError:
        return None


def finals_coverage(path: Path) -> FinalsCoverage | None:
    """Coverage of the ``finals2000A.all`` at ``path``; None if missing or not such a file."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    return _coverage_cached(str(path), st.st_mtime_ns, st.st_size)


def finals_path() -> Path:
    """The ``finals2000A.all`` runs use: the installed one if it reaches further than the
    shipped one (and is readable as such a table), else the shipped one."""
    shipped = shipped_finals_path()
    installed = installed_finals_path()
    mine = finals_coverage(installed)
    if mine is None:
        return shipped
    theirs = finals_coverage(shipped)
    if theirs is None or mine.predicted_until > theirs.predicted_until:
        return installed
    return shipped
