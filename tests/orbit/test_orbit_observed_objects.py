"""Observed positions of several objects in one table (``object`` column of compare): each
object's positions and straight-line velocities come from its own rows only, checked
against skyfield's SGP4 for two satellites whose rows interleave 10 s apart."""

from __future__ import annotations

from datetime import UTC, datetime, timedelta
from itertools import pairwise

import numpy as np
from skyfield.api import EarthSatellite

from speclight.orbit.observed_objects import _partition, object_layers
from speclight.orbit.timescale import load_timescale, time_from_utc
from speclight.orbit.tle import checksum

#: Calsphere 4A (the calsphere example's element set) and a second satellite in a plane 1.5 deg
#: of right ascension of the ascending node east (~110 km across the track at 48 deg N, seen
#: at the same time from one site).
TLE_A = (
    "1 01520U 65065H   20058.86916325  .00000035  00000-0  49354-4 0  9992",
    "2 01520  90.0403 128.7439 0072289 113.7399 336.8322 13.35807489655439",
)
_B2 = TLE_A[1][:17] + f"{128.7439 + 1.5:8.4f}" + TLE_A[1][25:68]
TLE_B = (TLE_A[0], _B2 + str(checksum(_B2)))
STEP_S = 10.0  # rows alternate between the two satellites every 10 s
N_ROWS = 12
#: Chord against arc over the 20 s between two rows of one satellite (Delta t = 20 s, mean
#: motion n = 9.7e-4 rad/s, v = 7.2 km/s): the chord's velocity differs from the tangent
#: at the chord's middle by v (n Delta t)^2 / 24 = 0.11 m/s; the chord's middle lies
#: r (n Delta t)^2 / 8 = 0.35 km inside the arc.
CHORD_VELOCITY_TOL_M_S = 0.3
CHORD_POSITION_TOL_M = 500.0


def _satellites() -> list[EarthSatellite]:
    ts = load_timescale()
    return [EarthSatellite(*TLE_A, "A", ts), EarthSatellite(*TLE_B, "B", ts)]


def _utc(seconds: np.ndarray) -> np.ndarray:
    start = np.datetime64("2020-02-29T21:16:00", "ns")
    return start + np.rint(np.asarray(seconds) * 1e9).astype("timedelta64[ns]")


def _skyfield(sat: EarthSatellite, seconds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    ts = load_timescale()
    start = datetime(2020, 2, 29, 21, 16, tzinfo=UTC)
    t = ts.from_datetimes([start + timedelta(seconds=float(s)) for s in seconds])
    at = sat.at(t)  # GCRS (skyfield's ICRS-aligned geocentric frame)
    return at.position.m.T, at.velocity.m_per_s.T


def test_interleaved_satellites_get_their_own_trajectories() -> None:
    sats = _satellites()
    seconds = np.arange(N_ROWS) * STEP_S
    which = np.arange(N_ROWS) % 2  # A, B, A, B, ... 10 s apart
    r = np.empty((N_ROWS, 3))
    for j, sat in enumerate(sats):
        r[which == j] = _skyfield(sat, seconds[which == j])[0]
    layers = object_layers(_utc(seconds), r, which.astype(np.intp), margin_s=1.5)
    assert len(layers) == 2  # their windows overlap: one layer each
    for layer in layers:
        (j,) = layer.objects
        own = seconds[which == j]
        assert layer.rows.tolist() == np.flatnonzero(which == j).tolist()
        # at the rows: the rows' positions
        at_rows, ok = layer.trajectory(time_from_utc(_utc(own)))
        assert ok.all()
        np.testing.assert_allclose(at_rows, r[which == j], atol=1e-6)
        # between two own rows (20 s apart): on the chord, the velocity the chord's
        mid = own[:-1] + 10.0
        r_mid, ok = layer.trajectory(time_from_utc(_utc(mid)))
        plus, _ = layer.trajectory(time_from_utc(_utc(mid + 0.5)))
        minus, _ = layer.trajectory(time_from_utc(_utc(mid - 0.5)))
        r_true, v_true = _skyfield(sats[j], mid)
        assert ok.all()
        np.testing.assert_allclose(r_mid, r_true, atol=CHORD_POSITION_TOL_M)
        np.testing.assert_allclose(plus - minus, v_true, atol=CHORD_VELOCITY_TOL_M_S)
        # beyond its last row by more than the margin: nothing
        _, ok = layer.trajectory(time_from_utc(_utc(own[-1:] + 5.0)))
        assert not ok.any()


def test_one_trajectory_through_both_would_be_wrong() -> None:
    # The reference failure: rows of two satellites ~190 km apart in one table give a
    # zigzag whose chord velocity is off by km/s (what compare did before objects).
    sats = _satellites()
    seconds = np.arange(N_ROWS) * STEP_S
    which = np.arange(N_ROWS) % 2
    r = np.empty((N_ROWS, 3))
    for j, sat in enumerate(sats):
        r[which == j] = _skyfield(sat, seconds[which == j])[0]
    (merged,) = object_layers(_utc(seconds), r, np.zeros(N_ROWS, np.intp), margin_s=1.5)
    mid = seconds[:-1] + 5.0
    plus, _ = merged.trajectory(time_from_utc(_utc(mid + 0.5)))
    minus, _ = merged.trajectory(time_from_utc(_utc(mid - 0.5)))
    assert np.linalg.norm(plus - minus - _skyfield(sats[0], mid)[1], axis=1).min() > 1e3


def test_objects_seen_one_after_the_other_share_a_layer() -> None:
    # Interval partitioning: as many layers as windows holding one time at most
    # (Kleinberg & Tardos 2006, sec. 4.1); windows that touch overlap.
    start = np.array([0.0, 5.0, 20.0, 21.0, 40.0, 10.0])
    stop = np.array([10.0, 15.0, 30.0, 22.0, 50.0, 19.0])
    layers = _partition(start, stop)
    assert len(layers) == 3  # at t = 10: intervals 0, 1 and 5
    for members in layers:
        spans = sorted(zip(start[members], stop[members], strict=True))
        assert all(a_stop < b_start for (_, a_stop), (b_start, _) in pairwise(spans))
    assert sorted(i for m in layers for i in m) == list(range(start.size))


def test_rows_without_a_position_leave_their_object_out() -> None:
    sats = _satellites()
    seconds = np.arange(4) * STEP_S
    r = _skyfield(sats[0], seconds)[0]
    r = np.vstack([r, np.full((2, 3), np.nan)])
    index = np.array([0, 0, 0, 0, 1, 1], dtype=np.intp)
    layers = object_layers(_utc(np.r_[seconds, 0.0, 10.0]), r, index, margin_s=1.5)
    assert [la.objects.tolist() for la in layers] == [[0]]
