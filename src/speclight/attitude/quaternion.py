"""Unit quaternions and frames from RA/Dec, vectorised over epochs.

Conventions (see :mod:`speclight.attitude`): quaternions are scalar-first
``(w, x, y, z)`` Hamilton quaternions stored in arrays of shape ``(..., 4)``; a
quaternion ``q`` represents the rotation from the body frame to the inertial (GCRS)
frame, ``v_gcrs = R(q) @ v_body = q ⊗ (0, v_body) ⊗ q*``. Composition follows the
matrices: ``R(p ⊗ q) = R(p) @ R(q)``.

All functions broadcast over leading dimensions. They never raise on a bad *row*
(a zero quaternion, a NaN): such rows come back as NaN, so one bad epoch marks its
own row only. Reference: F. L. Markley and J. L. Crassidis, *Fundamentals of
Spacecraft Attitude Determination and Control*, Springer (2014), ch. 2,
doi:10.1007/978-1-4939-0802-8 (we use the Hamilton product, not their ⊗ convention).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError

FloatArray = NDArray[np.float64]

#: Two unit vectors closer to parallel than this (|sin angle|) cannot define a frame.
PARALLEL_SIN_LIMIT = 1e-9


def _quat(q: ArrayLike) -> FloatArray:
    arr = np.asarray(q, dtype=np.float64)
    if arr.shape[-1:] != (4,):
        raise InputError(
            f"quaternion array has shape {arr.shape}; expected (..., 4) scalar-first (w, x, y, z)"
        )
    return arr


def _vec(v: ArrayLike) -> FloatArray:
    arr = np.asarray(v, dtype=np.float64)
    if arr.shape[-1:] != (3,):
        raise InputError(f"vector array has shape {arr.shape}; expected (..., 3)")
    return arr


def quat_multiply(p: ArrayLike, q: ArrayLike) -> FloatArray:
    """Hamilton product ``p ⊗ q`` (rotation ``q`` first, then ``p``).

    Parameters
    ----------
    p, q
        Quaternions, shape (..., 4), scalar-first; broadcast against each other.

    Returns
    -------
    numpy.ndarray
        Shape (..., 4), with ``R(p ⊗ q) = R(p) @ R(q)``.
    """
    a, b = _quat(p), _quat(q)
    w1, x1, y1, z1 = np.moveaxis(a, -1, 0)
    w2, x2, y2, z2 = np.moveaxis(b, -1, 0)
    return np.stack(
        (
            w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
        ),
        axis=-1,
    )


def quat_conjugate(q: ArrayLike) -> FloatArray:
    """Conjugate ``(w, -x, -y, -z)``: the inverse rotation for a unit quaternion."""
    out = _quat(q).copy()
    out[..., 1:] *= -1.0
    return out


def quat_normalize(q: ArrayLike) -> FloatArray:
    """Scale to unit norm; rows of zero or non-finite norm become NaN."""
    arr = _quat(q)
    norm = np.linalg.norm(arr, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        out = arr / norm
    bad = ~(np.isfinite(norm) & (norm > 0.0))
    return np.where(bad, np.nan, out)


def quat_to_matrix(q: ArrayLike) -> FloatArray:
    """Rotation matrices ``R(q)`` (body to inertial), shape (..., 3, 3).

    The quaternion is normalised first, so ``R`` is orthonormal even for a slightly
    non-unit input (Markley & Crassidis 2014, ch. 2).
    """
    w, x, y, z = np.moveaxis(quat_normalize(q), -1, 0)
    return np.stack(
        (
            np.stack((1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)), -1),
            np.stack((2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)), -1),
            np.stack((2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)), -1),
        ),
        axis=-2,
    )


def quat_from_matrix(matrix: ArrayLike) -> FloatArray:
    """Unit quaternions from rotation matrices (body to inertial), shape (..., 4).

    Uses Shepperd's method (pick the largest of the four squared components to divide
    by, which keeps the result accurate for every rotation; Markley & Crassidis 2014,
    ch. 2). The sign is fixed so that ``w >= 0``.
    """
    m = np.asarray(matrix, dtype=np.float64)
    if m.shape[-2:] != (3, 3):
        raise InputError(f"rotation matrix array has shape {m.shape}; expected (..., 3, 3)")
    m00, m11, m22 = m[..., 0, 0], m[..., 1, 1], m[..., 2, 2]
    trace = m00 + m11 + m22
    # 4 * component^2 for w, x, y, z
    cand = np.stack((1 + trace, 1 + 2 * m00 - trace, 1 + 2 * m11 - trace, 1 + 2 * m22 - trace), -1)
    pick = np.argmax(np.nan_to_num(cand, nan=-np.inf), axis=-1)
    s = 2.0 * np.sqrt(np.maximum(np.take_along_axis(cand, pick[..., None], -1)[..., 0], 0.0))
    m21, m12, m02 = m[..., 2, 1], m[..., 1, 2], m[..., 0, 2]
    m20, m10, m01 = m[..., 2, 0], m[..., 1, 0], m[..., 0, 1]
    d21, d02, d10 = m21 - m12, m02 - m20, m10 - m01
    s21, s02, s10 = m21 + m12, m02 + m20, m10 + m01
    with np.errstate(invalid="ignore", divide="ignore"):
        options = np.stack(
            (
                np.stack((s / 4, d21 / s, d02 / s, d10 / s), -1),
                np.stack((d21 / s, s / 4, s10 / s, s02 / s), -1),
                np.stack((d02 / s, s10 / s, s / 4, s21 / s), -1),
                np.stack((d10 / s, s02 / s, s21 / s, s / 4), -1),
            ),
            axis=-2,
        )
    q = np.take_along_axis(options, pick[..., None, None], axis=-2)[..., 0, :]
    q = np.where(q[..., :1] < 0.0, -q, q)
    return quat_normalize(q)


def quat_rotate(q: ArrayLike, v: ArrayLike) -> FloatArray:
    """Rotate vectors by ``q``: ``R(q) @ v`` (body components to inertial), shape (..., 3)."""
    return np.einsum("...ij,...j->...i", quat_to_matrix(q), _vec(v))


def quat_from_axis_angle(axis: ArrayLike, angle_rad: ArrayLike) -> FloatArray:
    """Quaternion of a right-handed rotation by ``angle_rad`` [rad] about ``axis``.

    Parameters
    ----------
    axis
        Rotation axes, shape (..., 3); normalised here (a zero axis gives a NaN row).
    angle_rad
        Rotation angles [rad], shape (...), broadcast against ``axis``.
    """
    ax = _vec(axis)
    norm = np.linalg.norm(ax, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        unit = np.where(norm > 0.0, ax / norm, np.nan)
    half = 0.5 * np.asarray(angle_rad, dtype=np.float64)[..., None]
    return np.concatenate((np.cos(half), np.sin(half) * unit), axis=-1)


def quat_to_axis_angle(q: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Axis (..., 3) and angle (...) [rad, in 0..pi] of the rotation ``q``.

    For the identity rotation the axis is returned as (0, 0, 1).
    """
    qn = quat_normalize(q)
    qn = np.where(qn[..., :1] < 0.0, -qn, qn)
    vec_norm = np.linalg.norm(qn[..., 1:], axis=-1)
    angle = 2.0 * np.arctan2(vec_norm, qn[..., 0])
    with np.errstate(invalid="ignore", divide="ignore"):
        axis = qn[..., 1:] / vec_norm[..., None]
    axis = np.where((vec_norm > 0.0)[..., None], axis, np.array([0.0, 0.0, 1.0]))
    return axis, angle


def unit_vector_from_radec(ra_deg: ArrayLike, dec_deg: ArrayLike) -> FloatArray:
    """Unit vectors, shape (..., 3), toward right ascension and declination [deg] (GCRS)."""
    ra = np.radians(np.asarray(ra_deg, dtype=np.float64))
    dec = np.radians(np.asarray(dec_deg, dtype=np.float64))
    return np.stack((np.cos(dec) * np.cos(ra), np.cos(dec) * np.sin(ra), np.sin(dec)), axis=-1)


def radec_from_unit_vector(v: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Right ascension in [0, 360) and declination in [-90, 90] [deg] of vectors (..., 3)."""
    arr = _vec(v)
    ra = np.degrees(np.arctan2(arr[..., 1], arr[..., 0])) % 360.0
    dec = np.degrees(np.arctan2(arr[..., 2], np.hypot(arr[..., 0], arr[..., 1])))
    return ra, dec


def frame_from_axes(
    z_axis: ArrayLike, x_hint: ArrayLike, *, field: str | None = None
) -> FloatArray:
    """Quaternion of the body frame whose z axis is ``z_axis`` and x axis is near ``x_hint``.

    The x axis is ``x_hint`` made orthogonal to z (Gram-Schmidt), y = z × x, so the
    frame is right-handed. Inputs are inertial vectors of shape (..., 3).

    Raises
    ------
    InputError
        If ``x_hint`` is parallel to ``z_axis`` (|sin angle| < 1e-9) or either is zero.
    """
    z = _vec(z_axis)
    xh = _vec(x_hint)
    z_norm = np.linalg.norm(z, axis=-1, keepdims=True)
    xh_norm = np.linalg.norm(xh, axis=-1, keepdims=True)
    if np.any(z_norm == 0.0) or np.any(xh_norm == 0.0):
        raise InputError("a frame axis is the zero vector; give a non-zero direction", field=field)
    z = z / z_norm
    xh = xh / xh_norm
    x = xh - np.sum(xh * z, axis=-1, keepdims=True) * z
    x_norm = np.linalg.norm(x, axis=-1, keepdims=True)
    if np.any(~(x_norm >= PARALLEL_SIN_LIMIT)):
        raise InputError(
            "the x-axis direction is parallel (or antiparallel) to the z axis, so it does "
            f"not fix the rotation about z (|sin angle| = {float(np.min(x_norm)):.3g} < "
            f"{PARALLEL_SIN_LIMIT}); choose an x direction at least a few degrees away from z",
            field=field,
        )
    x = x / x_norm
    y = np.cross(z, x)
    return quat_from_matrix(np.stack((x, y, z), axis=-1))


def frame_from_axes_radec(
    z_ra_deg: ArrayLike, z_dec_deg: ArrayLike, x_ra_deg: ArrayLike, x_dec_deg: ArrayLike
) -> FloatArray:
    """Body-to-GCRS quaternion of a frame given by its z and x axis directions.

    Parameters
    ----------
    z_ra_deg, z_dec_deg
        Right ascension and declination [deg] of the body z axis in GCRS.
    x_ra_deg, x_dec_deg
        Direction [deg] toward which the body x axis points; only its component
        orthogonal to z is used (Gram-Schmidt), so it need not be exactly at 90 deg.

    Returns
    -------
    numpy.ndarray
        Quaternion(s), shape (..., 4), broadcast over the inputs ((4,) for scalars).

    Raises
    ------
    InputError
        If the x direction is parallel or antiparallel to z.
    """
    z = unit_vector_from_radec(z_ra_deg, z_dec_deg)
    x = unit_vector_from_radec(x_ra_deg, x_dec_deg)
    z, x = np.broadcast_arrays(z, x)
    return frame_from_axes(z, x, field="attitude.x_axis_ra_deg/x_axis_dec_deg")
