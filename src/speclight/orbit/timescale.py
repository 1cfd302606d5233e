"""Offline time scales and the JPL ephemeris.

Nothing here touches the network. The leap-second and Earth-orientation table (IERS
``finals2000A.all``) is the one :func:`speclight.orbit.iers_files.finals_path` picks: the
copy shipped in ``skyfield-data``, or a newer one installed by ``speclight update-data``.
The JPL DE421 ephemeris is the file shipped in ``skyfield-data``. :func:`data_coverage`
says how far they reach.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np
from numpy.typing import NDArray
from skyfield.api import Loader
from skyfield.data import iers
from skyfield.timelib import Time, Timescale

from speclight.orbit.iers_files import (
    finals_coverage,
    finals_path,
    installed_finals_path,
    shipped_data_dir,
)


@functools.cache
def _loader() -> Loader:
    return Loader(shipped_data_dir(), verbose=False, expire=False)


@functools.cache
def load_timescale() -> Timescale:
    """Return the skyfield timescale built from the IERS table in use (offline).

    The table is the newest of the shipped and the installed ``finals2000A.all``
    (:func:`speclight.orbit.iers_files.finals_path`); call :func:`reload_tables` after
    installing one in a running process. The polar-motion table (x_p, y_p from the same
    file) is installed, so that skyfield's ``itrs`` frame and WGS84 positions include polar
    motion (a few tenths of an arcsecond, i.e. ~10 m at the Earth's surface); see skyfield's
    "Polar motion" documentation.
    """
    path = finals_path()
    # a Loader on the table's folder only opens the file that is there: it never downloads
    loader = Loader(str(path.parent), verbose=False, expire=False)
    ts = loader.timescale(builtin=False)
    with loader.open(path.name) as f:
        finals = iers.parse_x_y_dut1_from_finals_all(f)
    iers.install_polar_motion_table(ts, finals)
    return ts


def reload_tables() -> None:
    """Forget the timescale built so far: the next :func:`load_timescale` reads the table
    in use now (after ``speclight update-data`` in this process)."""
    load_timescale.cache_clear()


@functools.cache
def load_ephemeris() -> Any:
    """Return the JPL DE421 ephemeris shipped with skyfield-data (1900-2050)."""
    return _loader()("de421.bsp")


def time_from_utc(times_utc: NDArray[np.datetime64]) -> Time:
    """Convert UTC ``datetime64`` values to a skyfield :class:`~skyfield.timelib.Time`."""
    t64 = np.asarray(times_utc, dtype="datetime64[ns]")
    seconds = (t64 - np.datetime64("2000-01-01T12:00:00", "ns")) / np.timedelta64(1, "s")
    # Julian date split in a whole and a fractional part keeps sub-microsecond precision.
    days = np.floor(seconds / 86400.0)
    fraction = (seconds - days * 86400.0) / 86400.0
    ts = load_timescale()
    return ts.utc(2000, 1, 1.5 + days, 0, 0, fraction * 86400.0)


def data_coverage() -> dict[str, str]:
    """How far the Earth-orientation, leap-second and ephemeris tables in use reach.

    Returns
    -------
    dict
        ISO dates keyed by ``eop_measured_until``, ``eop_predicted_until``,
        ``leap_seconds_until`` and ``ephemeris``; ``eop_table``: the file in use.
    """
    path = finals_path()
    coverage = finals_coverage(path)
    measured = str(coverage.measured_until) if coverage else ""
    predicted = str(coverage.predicted_until) if coverage else ""
    which = "updated" if path == installed_finals_path() else "shipped in skyfield-data"
    return {
        "eop_measured_until": measured,
        "eop_predicted_until": predicted,
        "leap_seconds_until": predicted,
        "eop_table": f"{path} ({which}; `speclight update-data` refreshes it)",
        "ephemeris": "JPL DE421, 1899-07-29 to 2053-10-09",
    }
