"""Notices for a TLE far from the simulated epochs and for epochs past the IERS table."""

from __future__ import annotations

import numpy as np

from speclight.orbit import iers_files
from speclight.orbit.staleness import tables_notice, tle_age_notice

EPOCH = np.datetime64("2020-02-27T20:51:35", "ns")  # CALSPHERE 4A, the calsphere example
CALSPHERE_REV_PER_DAY = 13.35807489  # line 2, columns 53-63: a low orbit (period 108 min)


def _utc(*times: str) -> np.ndarray:
    return np.array(times, dtype="datetime64[ns]")


def test_a_tle_within_30_days_of_every_epoch_gives_no_notice() -> None:
    # 29 days before and 29 days after the element epoch
    assert tle_age_notice(EPOCH, _utc("2020-01-29T21:00", "2020-03-27T20:00")) is None


def test_an_old_tle_notice_says_how_old_and_what_it_means() -> None:
    # 2020-06-05T20:51:35 is 99 days after the epoch: 99 km to 297 km at 1-3 km per day
    notice = tle_age_notice(EPOCH, _utc("2020-06-05T20:51:35"), CALSPHERE_REV_PER_DAY)
    assert notice is not None
    assert "2020-02-27 20:51:35 UTC is 99 days" in notice
    assert "~99-297 km" in notice and "\n" not in notice
    # the farthest epoch counts, before the element epoch as well as after it
    notice = tle_age_notice(EPOCH, _utc("2019-11-19T20:51:35", "2020-02-28T00:00"))
    assert notice is not None and "is 100 days" in notice


def test_high_orbits_and_very_old_elements_give_no_misleading_number() -> None:
    geo = tle_age_notice(EPOCH, _utc("2020-06-05T20:51:35"), 1.0027)
    assert geo is not None and "km per day in low orbits" in geo and "off by" not in geo
    years = tle_age_notice(EPOCH, _utc("2026-06-05T00:00"), CALSPHERE_REV_PER_DAY)
    assert years is not None and "essentially unknown" in years


def test_epochs_past_the_last_day_of_the_table_are_reported() -> None:
    coverage = iers_files.finals_coverage(iers_files.finals_path())
    assert coverage is not None
    last_day = np.datetime64(coverage.predicted_until, "ns")
    assert tables_notice(np.array([last_day + np.timedelta64(23, "h")])) is None
    notice = tables_notice(np.array([last_day, last_day + np.timedelta64(1, "D")]))
    assert notice is not None
    assert "1 of 2 epochs" in notice and str(coverage.predicted_until) in notice
    assert "speclight update-data" in notice
