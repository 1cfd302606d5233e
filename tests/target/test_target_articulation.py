"""Articulated parts: the Sun-tracking law, posing, the angle table and its errors."""

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.target import Material, Reflectance
from speclight.target.articulation import (
    Joint,
    posed_target,
    read_angle_table,
    rotation_matrix,
)
from speclight.target.shapes import bus_array

WHITE = Material("w", "lambertian", Reflectance.constant(1.0))


def _array_normal(target):
    p = next(p for p in target.parts if p.name == "array")
    t = p.vertices_m[p.faces[0]]
    n = np.cross(t[1] - t[0], t[2] - t[0])
    return n / np.linalg.norm(n)


def test_sun_tracking_brings_the_posed_normal_closest_to_the_sun():
    # The best a single-axis hinge can do. Split the normal n = c a + p (c = n . a, p
    # perpendicular to the axis a): turning keeps c a and turns p, so the largest
    # n . s = c (a . s) + |p| sqrt(1 - (a . s)^2) (closed form; for a normal perpendicular to
    # the axis, the angle to the Sun is the complement of the Sun's elevation above the plane
    # perpendicular to the axis). Checked on the posed mesh itself (a tilted axis, so c != 0),
    # and against a brute-force scan of hinge angles.
    target = bus_array(WHITE)
    axis = np.array([0.3, -0.2, 1.0])
    a = axis / np.linalg.norm(axis)
    joint = Joint("array", tuple(axis), (0.0, 0.0, -1.0), (1.0, 0.0, 0.0), "sun_tracking")
    rng = np.random.default_rng(3)
    sun = rng.normal(size=(20, 3))
    sun /= np.linalg.norm(sun, axis=1, keepdims=True)
    angles = joint.angles_rad(sun, np.zeros(20, "datetime64[ns]"))
    scan = np.radians(np.arange(0.0, 360.0, 0.05))
    base = bus_array(WHITE)
    for s, t in zip(sun, angles, strict=True):
        n = _array_normal(posed_target(target, (joint,), np.array([t])))
        # the mesh normal of the array is +x at angle 0, as the joint's reference normal
        assert _array_normal(base) == pytest.approx([1.0, 0.0, 0.0], abs=1e-12)
        c = a[0]  # n = +x at angle 0
        assert n @ s == pytest.approx(c * (a @ s) + np.sqrt((1 - c**2) * (1 - (a @ s) ** 2)))
        best = max(rotation_matrix(a, u) @ np.array([1.0, 0.0, 0.0]) @ s for u in scan)
        assert n @ s >= best - 1e-9


def test_posing_turns_about_the_hinge_line():
    # Points on the hinge line stay; a point at distance d from it stays at distance d.
    target = bus_array(WHITE)
    hinge = np.array([0.5, 0.0, -1.0])
    joint = Joint("array", (0.0, 0.0, 1.0), tuple(hinge), (1.0, 0.0, 0.0), "sun_tracking")
    posed = posed_target(target, (joint,), np.array([np.radians(90.0)]))
    before = target.parts[2].vertices_m - hinge
    after = posed.parts[2].vertices_m - hinge
    np.testing.assert_allclose(np.hypot(after[:, 0], after[:, 1]), np.hypot(*before[:, :2].T))
    np.testing.assert_allclose(after[:, 2], before[:, 2])
    # +90 deg about z takes (x, y) to (-y, x)
    np.testing.assert_allclose(after[:, :2], np.c_[-before[:, 1], before[:, 0]], atol=1e-12)
    assert posed.parts[0] is target.parts[0]  # other parts are not moved


def test_angle_table_interpolates_and_refuses_epochs_outside(tmp_path):
    f = tmp_path / "angles.csv"
    f.write_text("time_utc,angle_deg\n2024-01-01T00:00:00Z,10\n2024-01-01T00:01:40Z,30\n")
    times, angles = read_angle_table(f, "target.articulation.array.table_file")
    joint = Joint("array", (0, 0, 1), (0, 0, 0), (1, 0, 0), "table", times, angles)
    at = np.array(["2024-01-01T00:00:25", "2024-01-01T00:01:40"], dtype="datetime64[ns]")
    got = np.degrees(joint.angles_rad(np.zeros((2, 3)), at))
    np.testing.assert_allclose(got, [15.0, 30.0])  # 10 + 20 * 25/100
    late = np.array(["2024-01-01T00:01:41"], dtype="datetime64[ns]")
    with pytest.raises(InputError, match="outside the angle table"):
        joint.angles_rad(np.zeros((1, 3)), late)


@pytest.mark.parametrize(
    "text, match",
    [
        ("time_utc,angle_deg\n2024-01-01T00:00:00Z,10\n", "need at least 2"),
        ("time_utc,angle_deg\n2024-01-01T00:00:00Z,10\n2024-01-01T00:00:00Z,11\n", "increasing"),
        ("time_utc,angle_deg\nyesterday,10\n2024-01-01T00:00:00Z,11\n", "line 2"),
    ],
)
def test_bad_angle_tables_name_the_problem(tmp_path, text, match):
    f = tmp_path / "a.csv"
    f.write_text(text)
    with pytest.raises(InputError, match=match):
        read_angle_table(f, "target.articulation.array.table_file")


def test_a_normal_along_the_axis_is_refused():
    with pytest.raises(InputError, match="not parallel to the axis"):
        Joint("array", (0, 0, 1), (0, 0, 0), (0, 0, 2), "sun_tracking")
