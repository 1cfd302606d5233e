"""Tabulated attitude: the CSV reader, slerp against scipy, no extrapolation.

References: scipy's ``Rotation``/``Slerp`` (an independent slerp: it interpolates the
rotation vector of the relative rotation, not the quaternion formula used here), the
table's knots themselves, and the conjugate as the inverse rotation (``gcrs_to_body``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from profile_pass import pass_scenario
from scipy.spatial.transform import Rotation, Slerp

from speclight.attitude import quat_conjugate
from speclight.attitude.quaternion_table import read_attitude_table, slerp_table
from speclight.errors import InputError
from speclight.scenario import parse_scenario
from speclight.schema import FLAG_ATTITUDE_UNDEFINED
from speclight.simulation.geometry_stage import scenario_geometry

#: Round-off of unit quaternions through a few trigonometric products.
ROUNDOFF = 1e-13
#: Renormalising a unit quaternion: sqrt of a 4-term sum and a division, <= 4 ulp of 1.
NORMALISE_ROUNDOFF = 4 * np.finfo(float).eps
T0 = np.datetime64("2019-08-30T02:22:00", "ns")


def _rotations_close(q_wxyz: np.ndarray, r: Rotation, atol: float) -> None:
    """Same rotations (q and -q are one rotation): compare the matrices."""
    expected = r.as_matrix()
    got = Rotation.from_quat(np.roll(q_wxyz, -1, axis=-1)).as_matrix()  # scipy: scalar last
    np.testing.assert_allclose(got, expected, atol=atol)


def _write(path: Path, times, q, frame: str | None = "body_to_gcrs") -> Path:
    lines = [f"# frame: {frame}"] if frame else []
    lines += ["# a comment", "time_utc,w,x,y,z"]
    lines += [
        f"{t}Z,{','.join(repr(float(c)) for c in row)}" for t, row in zip(times, q, strict=True)
    ]
    path.write_text("\n".join(lines) + "\n")
    return path


def _knots(n: int = 7, seed: int = 5):
    rng = np.random.default_rng(seed)
    steps_s = rng.uniform(10.0, 60.0, n - 1)
    times = T0 + np.concatenate(([0], np.cumsum(steps_s * 1e9))).astype("timedelta64[ns]")
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    q[2] *= -1.0 if q[1] @ q[2] > 0 else 1.0  # one pair on opposite hemispheres
    return times, q


def test_slerp_matches_scipy_at_midpoints_and_knots(tmp_path):
    times, q = _knots()
    table = read_attitude_table(_write(tmp_path / "att.csv", times, q))
    knots_s = (times - times[0]) / np.timedelta64(1, "s")
    reference = Slerp(knots_s, Rotation.from_quat(np.roll(q, -1, axis=1)))
    mid_s = 0.5 * (knots_s[1:] + knots_s[:-1])
    rng = np.random.default_rng(9)
    at_s = np.concatenate((mid_s, rng.uniform(knots_s[0], knots_s[-1], 50)))
    at = times[0] + np.rint(at_s * 1e9).astype("timedelta64[ns]")
    got, inside = slerp_table(table.times_utc, table.q_body_to_gcrs, at)
    assert inside.all()
    # the file holds 17 significant digits (repr), so the table is q itself
    exact_s = (at - times[0]) / np.timedelta64(1, "s")
    _rotations_close(got, reference(exact_s), atol=ROUNDOFF)
    np.testing.assert_allclose(np.linalg.norm(got, axis=1), 1.0, atol=ROUNDOFF)
    # at the knots: the tabulated quaternion itself (not its negative)
    at_knots, _ = slerp_table(table.times_utc, table.q_body_to_gcrs, times)
    np.testing.assert_allclose(at_knots[:-1], q[:-1], atol=ROUNDOFF)
    _rotations_close(at_knots[-1:], Rotation.from_quat(np.roll(q[-1:], -1, axis=1)), ROUNDOFF)


def test_epochs_outside_the_table_are_nan_not_extrapolated(tmp_path):
    times, q = _knots(3)
    table = read_attitude_table(_write(tmp_path / "att.csv", times, q))
    one_ns = np.timedelta64(1, "ns")
    at = np.array(
        [times[0] - one_ns, times[0], times[-1], times[-1] + one_ns, np.datetime64("NaT")]
    )
    got, inside = slerp_table(table.times_utc, table.q_body_to_gcrs, at)
    np.testing.assert_array_equal(inside, [False, True, True, False, False])
    assert np.isnan(got[~inside]).all() and np.isfinite(got[inside]).all()


def test_gcrs_to_body_rows_are_conjugated(tmp_path):
    times, q = _knots(3)
    default = read_attitude_table(_write(tmp_path / "a.csv", times, q, frame=None))
    inverse = read_attitude_table(_write(tmp_path / "b.csv", times, q, frame="GCRS->body"))
    # the reader normalises each row (a norm and four divisions: a few ulp of an O(1) value)
    np.testing.assert_allclose(default.q_body_to_gcrs, q, rtol=0, atol=NORMALISE_ROUNDOFF)
    np.testing.assert_allclose(
        inverse.q_body_to_gcrs, quat_conjugate(q), rtol=0, atol=NORMALISE_ROUNDOFF
    )


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("# frame: body_to_gcr\ntime_utc,w,x,y,z\n", "did you mean 'body_to_gcrs'"),
        ("time_utc,x,y,z,w\n2020-01-01T00:00:00Z,1,0,0,0\n", "column header"),
        ("time_utc,w,x,y,z\n2020-01-01T00:00:00Z,2,0,0,0\n2020-01-01T00:01:00Z,1,0,0,0\n",
         "norm 2"),
        ("time_utc,w,x,y,z\n2020-01-01T00:00:00Z,1,0,0,0\n", "1 data rows"),
        ("time_utc,w,x,y,z\n2020-01-01T00:01:00Z,1,0,0,0\n2020-01-01T00:00:00Z,1,0,0,0\n",
         "increase strictly"),
        ("time_utc,w,x,y,z\nyesterday,1,0,0,0\n2020-01-01T00:00:00Z,1,0,0,0\n", "line 2"),
    ],
)  # fmt: skip
def test_bad_tables_are_input_errors(tmp_path, text, message):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(InputError, match=message):
        read_attitude_table(path)


def test_pipeline_flags_epochs_outside_the_table(tmp_path):
    # the pass runs 02:20 .. 02:29 every 30 s; the table covers 02:22 .. 02:25:30
    times = T0 + np.array([0, 90, 210], dtype="timedelta64[s]").astype("timedelta64[ns]")
    q = Rotation.from_rotvec([[0, 0, 0], [0.3, 0.1, 0], [0.2, 0.5, 0.1]]).as_quat()
    _write(tmp_path / "att.csv", times, np.roll(q, 1, axis=1))
    d = pass_scenario({"model": "table", "file": "att.csv"})
    loaded = parse_scenario(yaml.safe_dump(d), source="test", base_dir=tmp_path)
    geo = scenario_geometry(loaded)
    inside = (geo.time_utc >= times[0]) & (geo.time_utc <= times[-1])
    assert inside.sum() == 8 and (~inside).sum() == 11
    undefined = (geo.flags & FLAG_ATTITUDE_UNDEFINED) != 0
    np.testing.assert_array_equal(undefined, ~inside)
    assert not geo.observable[~inside].any()
    assert np.isnan(geo.phase_vector_body[~inside]).all()
    reference = Slerp((times - T0) / np.timedelta64(1, "s"), Rotation.from_quat(q))
    _rotations_close(
        geo.quaternion_body_to_gcrs[inside],
        reference((geo.time_utc[inside] - T0) / np.timedelta64(1, "s")),
        atol=ROUNDOFF,
    )
