"""Notices for inputs too old (or too short) for the epochs of a run.

Two things make a run's geometry quietly wrong while every number still looks fine:

* **An old TLE.** SGP4 mean elements fitted to observations near their epoch drift away
  from the real orbit with time: for low orbits the along-track error grows by roughly
  1 to 3 km per day from the epoch (Vallado & Cefola 2012, "Two-line element sets:
  practice and use", 63rd International Astronautical Congress; Flohrer, Krag & Klinkrad
  2008, "Assessment and categorization of TLE orbit errors for the US SSN catalogue", AMOS
  Conference). A TLE more than
  :data:`TLE_AGE_LIMIT_DAYS` from the window is reported.
* **Epochs past the Earth-orientation and leap-second table.** Beyond its last day
  skyfield extrapolates UT1-UTC and polar motion (the IERS predictions themselves are good
  to about 0.25 ms x days^0.75 in UT1, IERS Bulletin A, i.e. ~20 ms or ~10 m at the
  equator a year out) and knows of no leap second announced since (1 s of time is ~7 km
  along a low orbit).

Each is one :class:`StaleInputWarning`, which the command line prints as a one-line
``notice:`` on stderr, once per process: the same notice never twice, and the
Earth-orientation one (:class:`EarthOrientationWarning`, whose counts differ from one run
to the next, e.g. per site of ``speclight compare``) only the first time.
"""

from __future__ import annotations

import warnings

import numpy as np
from numpy.typing import NDArray

from speclight.orbit.iers_files import finals_coverage, finals_path

#: A TLE whose epoch is further than this from an epoch of the run is reported [day].
TLE_AGE_LIMIT_DAYS = 30.0
#: Along-track error growth of SGP4 for low orbits, low and high end [km per day of age]
#: (Vallado & Cefola 2012; see the module docstring).
LEO_ERROR_KM_PER_DAY = (1.0, 3.0)
#: Beyond this along-track error [km] the linear estimate is not worth quoting.
ESSENTIALLY_UNKNOWN_KM = 1000.0
#: Mean motion above which an orbit is low (period under 128 min, below ~2,000 km) [rev/day].
LEO_MIN_MEAN_MOTION_REV_PER_DAY = 11.25


class StaleInputWarning(UserWarning):
    """An input (TLE, Earth-orientation table) is too old for the epochs of a run."""


class EarthOrientationWarning(StaleInputWarning):
    """Epochs lie past the end of the Earth-orientation and leap-second table: one table
    serves the whole process, so the command line says so once."""


def _day(t: np.datetime64 | NDArray[np.datetime64]) -> str:
    return str(np.datetime_as_string(t, unit="s")).replace("T", " ")


def tle_age_notice(
    tle_epoch: np.datetime64,
    time_utc: NDArray[np.datetime64],
    mean_motion_rev_per_day: float | None = None,
) -> str | None:
    """The notice for a TLE whose epoch is more than :data:`TLE_AGE_LIMIT_DAYS` from an
    epoch of the run, or None.

    Parameters
    ----------
    tle_epoch
        The element set's epoch, UTC.
    time_utc
        The run's epochs, UTC ``datetime64``.
    mean_motion_rev_per_day
        The TLE's mean motion (line 2, columns 53-63): for low orbits the notice estimates
        the position error.
    """
    t = np.asarray(time_utc, dtype="datetime64[ns]")
    epoch = np.asarray(tle_epoch, dtype="datetime64[ns]")
    age_days = float(np.max(np.abs(t - epoch)) / np.timedelta64(1, "D"))
    if not age_days > TLE_AGE_LIMIT_DAYS:
        return None
    low = mean_motion_rev_per_day is not None and (
        mean_motion_rev_per_day >= LEO_MIN_MEAN_MOTION_REV_PER_DAY
    )
    lo, hi = LEO_ERROR_KM_PER_DAY
    effect = "SGP4 errors grow with the elements' age (by km per day in low orbits)"
    if low:
        effect = f"for this low orbit the along-track error grows by ~{lo:.0f}-{hi:.0f} km per day"
        if lo * age_days <= ESSENTIALLY_UNKNOWN_KM:
            low_km, high_km = lo * age_days, hi * age_days
            effect += f", i.e. positions may be off by ~{low_km:,.0f}-{high_km:,.0f} km"
        else:
            effect += ": at this age the position along the orbit is essentially unknown"
    return (
        f"the TLE's epoch {_day(epoch)} UTC is {age_days:,.0f} days from the simulated "
        f"epochs (more than {TLE_AGE_LIMIT_DAYS:.0f}): {effect}; use elements from within a "
        "few days of the window"
    )


def tables_notice(time_utc: NDArray[np.datetime64]) -> str | None:
    """The notice for epochs after the last day of the Earth-orientation and leap-second
    table in use, or None."""
    path = finals_path()
    coverage = finals_coverage(path)
    if coverage is None:
        return None
    t = np.asarray(time_utc, dtype="datetime64[ns]")
    end = coverage.predicted_until + np.timedelta64(1, "D")  # the last day, whole
    late = t >= end
    if not late.any():
        return None
    return (
        f"{int(late.sum())} of {t.size} epochs (up to {_day(t.max())} UTC) lie after "
        f"{coverage.predicted_until}, the end of the Earth-orientation and leap-second table "
        f"({path.name}): UT1 and polar motion are extrapolated (observer position errors of "
        "metres, growing with time) and a leap second announced since would be missed (1 s "
        "is ~7 km along a low orbit); `speclight update-data` refreshes the table"
    )


def warn_tle_age(
    tle_epoch: np.datetime64,
    time_utc: NDArray[np.datetime64],
    mean_motion_rev_per_day: float | None = None,
) -> None:
    """Issue :func:`tle_age_notice` as a :class:`StaleInputWarning`, if there is one."""
    notice = tle_age_notice(tle_epoch, time_utc, mean_motion_rev_per_day)
    if notice:
        warnings.warn(notice, StaleInputWarning, stacklevel=2)


def warn_past_tables(time_utc: NDArray[np.datetime64]) -> None:
    """Issue :func:`tables_notice` as an :class:`EarthOrientationWarning`, if there is one."""
    notice = tables_notice(time_utc)
    if notice:
        warnings.warn(notice, EarthOrientationWarning, stacklevel=2)
