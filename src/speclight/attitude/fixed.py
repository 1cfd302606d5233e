"""Fixed inertial attitude: the same body-to-GCRS rotation at every epoch."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from speclight.attitude.quaternion import FloatArray, frame_from_axes_radec
from speclight.errors import InputError

#: How far from unit norm a user quaternion may be before we call it a mistake.
QUATERNION_NORM_TOLERANCE = 1e-3


def validate_quaternion(quaternion: ArrayLike, field: str) -> FloatArray:
    """Check one user quaternion (4,) scalar-first and return it normalised.

    Raises
    ------
    InputError
        If it is not 4 finite numbers or its norm differs from 1 by more than 1e-3.
    """
    q = np.asarray(quaternion, dtype=np.float64)
    if q.shape != (4,) or not np.all(np.isfinite(q)):
        raise InputError(
            f"quaternion = {np.asarray(quaternion).tolist()} must be 4 finite numbers, "
            "scalar first: [w, x, y, z]",
            field=field,
        )
    norm = float(np.linalg.norm(q))
    if abs(norm - 1.0) > QUATERNION_NORM_TOLERANCE:
        raise InputError(
            f"quaternion = {q.tolist()} has norm {norm:.6g}; a rotation needs a unit "
            f"quaternion (norm within {QUATERNION_NORM_TOLERANCE} of 1): divide it by its norm",
            field=field,
        )
    return q / norm


def fixed_attitude(
    n_epochs: int,
    quaternion: ArrayLike | None = None,
    *,
    z_ra_deg: float | None = None,
    z_dec_deg: float | None = None,
    x_ra_deg: float | None = None,
    x_dec_deg: float | None = None,
) -> FloatArray:
    """Constant body-to-GCRS attitude repeated over ``n_epochs`` epochs.

    Give either ``quaternion`` or all four of ``z_ra_deg, z_dec_deg, x_ra_deg,
    x_dec_deg`` (body z axis direction, and the direction the body x axis points
    toward, orthogonalised against z). With neither, the body axes are the GCRS axes.

    Parameters
    ----------
    n_epochs
        Number of epochs N (>= 0).
    quaternion
        Scalar-first unit quaternion (4,), body to GCRS.
    z_ra_deg, z_dec_deg, x_ra_deg, x_dec_deg
        Axis directions [deg] in GCRS.

    Returns
    -------
    numpy.ndarray
        Quaternions, shape (N, 4).

    Raises
    ------
    InputError
        If both or an incomplete set of the two forms are given, the quaternion is not
        a unit quaternion, or x is parallel to z.
    """
    if int(n_epochs) != n_epochs or n_epochs < 0:
        raise InputError(f"n_epochs = {n_epochs!r} must be a non-negative integer")
    radec = {
        "z_ra_deg": z_ra_deg,
        "z_dec_deg": z_dec_deg,
        "x_ra_deg": x_ra_deg,
        "x_dec_deg": x_dec_deg,
    }
    given = [name for name, value in radec.items() if value is not None]
    if quaternion is not None and given:
        raise InputError(
            f"give either quaternion or the axis directions ({', '.join(given)}), not both",
            field="attitude",
        )
    if quaternion is not None:
        q = validate_quaternion(quaternion, "attitude.quaternion")
    elif given:
        q = _from_directions(radec)
    else:
        q = np.array([1.0, 0.0, 0.0, 0.0])
    return np.tile(q, (int(n_epochs), 1))


def _from_directions(radec: dict[str, float | None]) -> FloatArray:
    """The quaternion of the axis directions, all four of which must be given."""
    missing = [name for name in radec if radec[name] is None]
    if missing:
        raise InputError(
            f"a fixed frame from directions needs all of z_ra_deg, z_dec_deg, x_ra_deg, "
            f"x_dec_deg; missing: {', '.join(missing)}",
            field="attitude",
        )
    z_ra, z_dec, x_ra, x_dec = (float(v) for v in radec.values() if v is not None)
    return frame_from_axes_radec(z_ra, z_dec, x_ra, x_dec)
