"""Quaternion algebra and RA/Dec frames against independent references.

References: scipy.spatial.transform.Rotation (an independent implementation; it stores
quaternions scalar-LAST, so we reorder), astropy's spherical-to-Cartesian conversion,
and the defining properties of rotation matrices (R^T R = I, det R = +1).
"""

from __future__ import annotations

import numpy as np
import pytest
from astropy.coordinates import spherical_to_cartesian
from scipy.spatial.transform import Rotation

from speclight.attitude import (
    frame_from_axes_radec,
    quat_conjugate,
    quat_from_axis_angle,
    quat_from_matrix,
    quat_multiply,
    quat_normalize,
    quat_rotate,
    quat_to_axis_angle,
    quat_to_matrix,
    radec_from_unit_vector,
    unit_vector_from_radec,
)
from speclight.errors import InputError

#: Float64 round-off on O(1) rotation-matrix elements after a handful of operations.
ROUNDOFF = 1e-14
#: Angles [deg] recovered through trigonometric round trips (arctan2 of O(1) numbers).
ANGLE_ROUNDOFF_DEG = 1e-11


def _random_quats(n: int, seed: int = 7) -> np.ndarray:
    rng = np.random.default_rng(seed)
    q = rng.normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def _scalar_last(q: np.ndarray) -> np.ndarray:
    return np.roll(q, -1, axis=-1)


def test_matrix_matches_scipy_rotation() -> None:
    q = _random_quats(50)
    reference = Rotation.from_quat(_scalar_last(q)).as_matrix()
    np.testing.assert_allclose(quat_to_matrix(q), reference, atol=ROUNDOFF)


def test_matrix_round_trip_covers_all_shepperd_branches() -> None:
    # Random rotations plus rotations by ~pi about each axis, where w ~ 0 and each of
    # x, y, z in turn is the largest component (the branches of Shepperd's method).
    q = np.concatenate(
        (_random_quats(200), quat_from_axis_angle(np.eye(3), np.full(3, np.pi - 1e-3)))
    )
    back = quat_from_matrix(quat_to_matrix(q))
    same_rotation = np.abs(np.sum(back * q, axis=1))  # |<q, q'>| = 1 for q' = +-q
    np.testing.assert_allclose(same_rotation, 1.0, atol=ROUNDOFF)
    assert np.all(back[:, 0] >= 0.0)


def test_from_matrix_matches_scipy() -> None:
    matrices = Rotation.random(30, random_state=3).as_matrix()
    q = quat_from_matrix(matrices)
    q_ref = Rotation.from_matrix(matrices).as_quat()[:, [3, 0, 1, 2]]
    np.testing.assert_allclose(np.abs(np.sum(q * q_ref, axis=1)), 1.0, atol=ROUNDOFF)


def test_product_composes_like_matrices() -> None:
    # R(p ⊗ q) = R(p) R(q), the Hamilton convention (Markley & Crassidis 2014, ch. 2).
    p, q = _random_quats(20, 1), _random_quats(20, 2)
    np.testing.assert_allclose(
        quat_to_matrix(quat_multiply(p, q)), quat_to_matrix(p) @ quat_to_matrix(q), atol=ROUNDOFF
    )
    composed = Rotation.from_quat(_scalar_last(p)) * Rotation.from_quat(_scalar_last(q))
    np.testing.assert_allclose(
        quat_to_matrix(quat_multiply(p, q)), composed.as_matrix(), atol=1e-13
    )


def test_conjugate_is_inverse_and_rotate_matches_matrix() -> None:
    q = _random_quats(20)
    identity = quat_multiply(q, quat_conjugate(q))
    np.testing.assert_allclose(identity, np.tile([1.0, 0, 0, 0], (20, 1)), atol=ROUNDOFF)
    v = np.random.default_rng(5).normal(size=(20, 3))
    np.testing.assert_allclose(
        quat_rotate(q, v), Rotation.from_quat(_scalar_last(q)).apply(v), atol=1e-13
    )


def test_axis_angle_matches_scipy_rotvec() -> None:
    rng = np.random.default_rng(11)
    axis = rng.normal(size=(25, 3))
    angle = rng.uniform(0.0, np.pi, 25)
    unit = axis / np.linalg.norm(axis, axis=1, keepdims=True)
    reference = Rotation.from_rotvec(unit * angle[:, None]).as_matrix()
    q = quat_from_axis_angle(axis, angle)
    np.testing.assert_allclose(quat_to_matrix(q), reference, atol=ROUNDOFF)
    axis_back, angle_back = quat_to_axis_angle(q)
    np.testing.assert_allclose(angle_back, angle, atol=1e-13)
    np.testing.assert_allclose(axis_back, unit, atol=1e-12)


def test_normalize_marks_bad_rows_nan() -> None:
    q = np.array([[2.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0], [np.nan, 1.0, 0.0, 0.0]])
    out = quat_normalize(q)
    np.testing.assert_allclose(out[0], [1.0, 0.0, 0.0, 0.0])
    assert np.all(np.isnan(out[1:]))


def test_unit_vector_matches_astropy() -> None:
    ra = np.array([0.0, 45.0, 123.4, 270.0, 359.9])
    dec = np.array([0.0, -30.0, 60.0, 89.9, -89.0])
    x, y, z = spherical_to_cartesian(1.0, np.radians(dec), np.radians(ra))
    np.testing.assert_allclose(
        unit_vector_from_radec(ra, dec), np.stack((x, y, z), -1), atol=ROUNDOFF
    )
    ra_back, dec_back = radec_from_unit_vector(unit_vector_from_radec(ra, dec))
    np.testing.assert_allclose(ra_back, ra, atol=ANGLE_ROUNDOFF_DEG)
    np.testing.assert_allclose(dec_back, dec, atol=ANGLE_ROUNDOFF_DEG)


def test_frame_from_radec_is_orthonormal_right_handed_and_points_right() -> None:
    rng = np.random.default_rng(3)
    z_ra, z_dec = rng.uniform(0, 360, 40), rng.uniform(-89, 89, 40)
    x_ra, x_dec = rng.uniform(0, 360, 40), rng.uniform(-89, 89, 40)
    q = frame_from_axes_radec(z_ra, z_dec, x_ra, x_dec)
    r = quat_to_matrix(q)
    np.testing.assert_allclose(
        r.transpose(0, 2, 1) @ r, np.broadcast_to(np.eye(3), r.shape), atol=ROUNDOFF
    )
    np.testing.assert_allclose(np.linalg.det(r), 1.0, atol=ROUNDOFF)
    z_dir = unit_vector_from_radec(z_ra, z_dec)
    x_hint = unit_vector_from_radec(x_ra, x_dec)
    np.testing.assert_allclose(r[:, :, 2], z_dir, atol=ROUNDOFF)  # body z on the z direction
    # body x lies in the plane of z and the x hint, on the hint's side (Gram-Schmidt)
    np.testing.assert_allclose(
        np.einsum("ni,ni->n", r[:, :, 0], np.cross(z_dir, x_hint)), 0.0, atol=1e-13
    )
    assert np.all(np.einsum("ni,ni->n", r[:, :, 0], x_hint) > 0.0)


def test_frame_from_radec_exact_axes() -> None:
    # z toward the celestial pole, x toward the vernal equinox: the identity rotation.
    q = frame_from_axes_radec(0.0, 90.0, 0.0, 0.0)
    np.testing.assert_allclose(quat_to_matrix(q), np.eye(3), atol=ROUNDOFF)


@pytest.mark.parametrize("x_radec", [(10.0, 20.0), (190.0, -20.0)])
def test_frame_rejects_x_parallel_to_z(x_radec: tuple[float, float]) -> None:
    with pytest.raises(InputError, match="parallel"):
        frame_from_axes_radec(10.0, 20.0, *x_radec)
