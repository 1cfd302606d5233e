"""Two-axis pointing: one body axis on a direction, a second as close as possible to another.

The construction (the "align-constrain" or TRIAD frame; Markley & Crassidis 2014,
*Fundamentals of Spacecraft Attitude Determination and Control*, sec. 5.2,
doi:10.1007/978-1-4939-0802-8) builds an orthonormal triad from each pair,

``e1 = b1,  e2 = unit(b1 × b2),  e3 = e1 × e2``   (body vectors ``b1``, ``b2``)

``f1 = t1,  f2 = unit(t1 × t2),  f3 = f1 × f2``   (GCRS directions ``t1``, ``t2``)

and takes the rotation ``R = [f1 f2 f3] [e1 e2 e3]^T`` (body to GCRS). ``R b1 = t1``
exactly; ``R b2`` lies in the plane of ``t1`` and ``t2`` on ``t2``'s side, which is the
closest ``b2`` can come to ``t2`` while ``b1`` stays on ``t1``. The rotation is undefined
where ``t1`` and ``t2`` are parallel: those rows are NaN (the caller flags them).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from speclight.attitude.quaternion import PARALLEL_SIN_LIMIT, FloatArray, quat_from_matrix
from speclight.errors import InputError


def _unit_rows(v: FloatArray) -> tuple[FloatArray, FloatArray]:
    norm = np.linalg.norm(v, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return v / norm, norm[..., 0]


def body_axis(value: ArrayLike, field: str) -> FloatArray:
    """A user's body-frame axis (3,), normalised.

    Raises
    ------
    InputError
        If it is not three finite numbers of non-zero length.
    """
    b = np.asarray(value, dtype=np.float64)
    norm = float(np.linalg.norm(b)) if b.shape == (3,) else 0.0
    if b.shape != (3,) or not np.all(np.isfinite(b)) or not norm > 0.0:
        raise InputError(
            f"{np.asarray(value).tolist()} must be a non-zero body-frame vector [x, y, z]",
            field=field,
        )
    return b / norm


def body_triad(primary_body: ArrayLike, secondary_body: ArrayLike, field: str) -> FloatArray:
    """Columns ``e1, e2, e3`` (3, 3) of the body triad of two body axes.

    Raises
    ------
    InputError
        If an axis is zero or not finite, or the two are parallel (|sin angle| < 1e-9):
        then the second does not fix the rotation about the first.
    """
    b1 = body_axis(primary_body, f"{field} (primary axis)")
    b2 = body_axis(secondary_body, f"{field} (secondary axis)")
    e2 = np.cross(b1, b2)
    sin = float(np.linalg.norm(e2))
    if sin < PARALLEL_SIN_LIMIT:
        raise InputError(
            f"the secondary body axis {np.round(b2, 6).tolist()} is parallel to the pointing "
            f"axis {np.round(b1, 6).tolist()}, so it does not fix the rotation about it; "
            "choose two different body axes (e.g. [0, 0, 1] and [1, 0, 0])",
            field=field,
        )
    e2 /= sin
    return np.stack((b1, e2, np.cross(b1, e2)), axis=-1)


def align_constrain(
    primary_body: ArrayLike,
    primary_gcrs: ArrayLike,
    secondary_body: ArrayLike,
    secondary_gcrs: ArrayLike,
    *,
    field: str = "attitude",
) -> FloatArray:
    """Body-to-GCRS quaternions putting one body axis on a direction, a second near another.

    Parameters
    ----------
    primary_body, secondary_body
        Body-frame axes (3,), not parallel (normalised here).
    primary_gcrs, secondary_gcrs
        GCRS directions (N, 3) or (3,), any length (normalised here).
    field
        Scenario field named in errors.

    Returns
    -------
    numpy.ndarray
        Quaternions (N, 4). Rows where a direction is zero or not finite, or the two
        directions are parallel (|sin angle| < 1e-9), are NaN.

    Raises
    ------
    InputError
        If the body axes are zero or parallel.
    """
    e = body_triad(primary_body, secondary_body, field)
    t1 = np.atleast_2d(np.asarray(primary_gcrs, dtype=np.float64))
    t2 = np.atleast_2d(np.asarray(secondary_gcrs, dtype=np.float64))
    t1, t2 = np.broadcast_arrays(t1, t2)
    f1, n1 = _unit_rows(t1)
    f2, sin = _unit_rows(np.cross(f1, _unit_rows(t2)[0]))
    f = np.stack((f1, f2, np.cross(f1, f2)), axis=-1)
    with np.errstate(invalid="ignore"):
        bad = ~((n1 > 0.0) & (sin >= PARALLEL_SIN_LIMIT))
    f[bad] = np.eye(3)  # keep the conversion quiet; the rows are set to NaN below
    q = quat_from_matrix(f @ e.T)
    q[bad] = np.nan
    return q
