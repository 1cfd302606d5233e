"""Offline time scales and the JPL ephemeris, from the ``skyfield-data`` package.

Nothing here touches the network: the leap-second and Earth-orientation table
(IERS ``finals2000A.all``) and the JPL DE421 ephemeris are the files shipped in
``skyfield-data``. :func:`data_coverage` says how far they reach.
"""

from __future__ import annotations

import functools
import warnings
from typing import Any

import numpy as np
from numpy.typing import NDArray
from skyfield.api import Loader
from skyfield.data import iers
from skyfield.timelib import Time, Timescale


@functools.cache
def _data_path() -> str:
    with warnings.catch_warnings():
        # skyfield-data warns once its table's prediction horizon has passed; how far the
        # tables reach is reported by ``speclight info`` (``data_coverage``) instead.
        warnings.simplefilter("ignore", RuntimeWarning)
        import skyfield_data

        return str(skyfield_data.get_skyfield_data_path())


@functools.cache
def _loader() -> Loader:
    return Loader(_data_path(), verbose=False, expire=False)


@functools.cache
def load_timescale() -> Timescale:
    """Return the skyfield timescale built from the shipped IERS table (offline).

    The polar-motion table (x_p, y_p from the same ``finals2000A.all``) is installed, so
    that skyfield's ``itrs`` frame and WGS84 positions include polar motion (a few tenths
    of an arcsecond, i.e. ~10 m at the Earth's surface); see skyfield's "Polar motion"
    documentation.
    """
    ts = _loader().timescale(builtin=False)
    with _loader().open("finals2000A.all") as f:
        finals = iers.parse_x_y_dut1_from_finals_all(f)
    iers.install_polar_motion_table(ts, finals)
    return ts


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
    """How far the shipped Earth-orientation, leap-second and ephemeris tables reach.

    Returns
    -------
    dict
        ISO dates keyed by ``eop_measured_until``, ``eop_predicted_until``,
        ``leap_seconds_until`` and ``ephemeris``.
    """
    path = _data_path() + "/finals2000A.all"
    last_measured = last_any = ""
    with open(path) as f:
        for line in f:
            if len(line) < 68 or not line[7:15].strip():
                continue
            mjd = float(line[7:15])
            flag = line[16]
            date = str(np.datetime64("1858-11-17") + np.timedelta64(int(mjd), "D"))
            if line[58:68].strip():
                last_any = date
                if flag == "I":
                    last_measured = date
    return {
        "eop_measured_until": last_measured,
        "eop_predicted_until": last_any,
        "leap_seconds_until": last_any,
        "ephemeris": "JPL DE421, 1899-07-29 to 2053-10-09",
    }
