"""Inertia tensor validation and principal axes."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.attitude.quaternion import FloatArray
from speclight.errors import InputError

FIELD = "attitude.inertia_kg_m2"

#: Allowed asymmetry |I - I^T| relative to the largest element (float round-off of a
#: tensor computed elsewhere, not a physically different body).
SYMMETRY_RTOL = 1e-9
#: Slack in the triangle inequality I_i + I_j >= I_k, relative to I_k: a flat plate
#: satisfies it with equality, which round-off may break by a few ulp.
TRIANGLE_RTOL = 1e-9
#: Principal moments closer than this (relative to the largest) are made exactly equal,
#: so that an axisymmetric body given as a rotated tensor is treated as axisymmetric.
DEGENERATE_RTOL = 1e-12


@dataclass(frozen=True)
class PrincipalFrame:
    """Principal moments and axes of a rigid body.

    Attributes
    ----------
    moments_kg_m2
        Principal moments of inertia [kg m^2], shape (3,), ascending.
    axes
        Rotation matrix (3, 3) whose columns are the principal axes expressed in the
        body frame (det = +1), so ``v_body = axes @ v_principal``.
    """

    moments_kg_m2: FloatArray
    axes: FloatArray


def _fmt(value: ArrayLike) -> str:
    return str(np.asarray(value).tolist())


def _tensor(inertia_kg_m2: ArrayLike) -> NDArray[np.float64]:
    """The (3, 3) tensor of three principal moments or of a tensor, finite."""
    tensor = np.asarray(inertia_kg_m2, dtype=np.float64)
    if tensor.shape not in ((3,), (3, 3)):
        raise InputError(
            f"inertia_kg_m2 = {_fmt(inertia_kg_m2)} has shape {tensor.shape}; give the three "
            "principal moments [I1, I2, I3] or a 3x3 symmetric tensor [kg m^2]",
            field=FIELD,
        )
    if not np.all(np.isfinite(tensor)):
        raise InputError(
            f"inertia_kg_m2 = {_fmt(inertia_kg_m2)} contains a non-finite value", field=FIELD
        )
    return np.diag(tensor) if tensor.shape == (3,) else tensor


def principal_frame(inertia_kg_m2: ArrayLike) -> PrincipalFrame:
    """Validate an inertia tensor and diagonalise it.

    Parameters
    ----------
    inertia_kg_m2
        Principal moments (3,) along the body axes, or the full tensor (3, 3) in the
        body frame [kg m^2].

    Returns
    -------
    PrincipalFrame
        Ascending principal moments and a right-handed set of principal axes.

    Raises
    ------
    InputError
        (field ``attitude.inertia_kg_m2``) if the shape is wrong, a value is not
        finite, the tensor is not symmetric or not positive definite, or the principal
        moments violate the triangle inequality ``I1 + I2 >= I3`` (no rigid body has
        such moments; Goldstein, Poole & Safko, *Classical Mechanics*, 3rd ed., ch. 5).
    """
    tensor = _tensor(inertia_kg_m2)
    scale = float(np.max(np.abs(tensor)))
    asym = float(np.max(np.abs(tensor - tensor.T)))
    if asym > SYMMETRY_RTOL * scale:
        raise InputError(
            f"inertia_kg_m2 = {_fmt(inertia_kg_m2)} is not symmetric (largest |I_ij - I_ji| = "
            f"{asym:.3g}); an inertia tensor must equal its transpose: check the "
            "off-diagonal products of inertia",
            field=FIELD,
        )
    tensor = 0.5 * (tensor + tensor.T)
    moments, axes = np.linalg.eigh(tensor)
    if not moments[0] > 0.0:
        raise InputError(
            f"inertia_kg_m2 = {_fmt(inertia_kg_m2)} is not positive definite (principal "
            f"moments {_fmt(moments)}); every principal moment of a body with mass must be "
            "> 0 [kg m^2]",
            field=FIELD,
        )
    if moments[0] + moments[1] < moments[2] * (1.0 - TRIANGLE_RTOL):
        raise InputError(
            f"inertia_kg_m2 = {_fmt(inertia_kg_m2)} has principal moments {_fmt(moments)} with "
            f"I1 + I2 = {moments[0] + moments[1]:.6g} < I3 = {moments[2]:.6g}; no rigid body "
            "has these (triangle inequality I1 + I2 >= I3): check the units and values",
            field=FIELD,
        )
    # Snap near-degenerate moments so that axisymmetric bodies are exactly axisymmetric.
    for i in range(2):
        if moments[i + 1] - moments[i] <= DEGENERATE_RTOL * moments[2]:
            mean = 0.5 * (moments[i] + moments[i + 1])
            moments[i] = moments[i + 1] = mean
    if moments[2] - moments[0] <= DEGENERATE_RTOL * moments[2]:
        moments[:] = np.mean(moments)
    if np.linalg.det(axes) < 0.0:
        axes[:, 0] *= -1.0
    return PrincipalFrame(moments_kg_m2=moments, axes=axes)
