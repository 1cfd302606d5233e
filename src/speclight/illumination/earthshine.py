"""Earthshine: sunlight reflected by the Earth onto the target, as directional sources.

The Earth is a Lambertian sphere of radius :data:`~speclight.constants.EARTH_MEAN_RADIUS_M`
and albedo ``a``; a point ``p = R u`` of it lit by the Sun (direction ``s``) has the radiance
``L = a E_sun max(u . s, 0) / pi``. The target at ``t`` sees the cap ``u . t / |t| >=
R / |t|``; an element ``dA`` of it, at distance ``rho`` and emission cosine ``cos e = u . (t -
p) / rho``, gives a surface whose normal points at it the irradiance ``L cos e dA / rho^2``.

The cap is cut into ``K`` cells of equal area (a golden-angle spiral, equal steps in
``cos theta`` about the sub-target point, ``dA = 2 pi R^2 (1 - R / |t|) / K``); each cell
becomes a directional source from the target toward its centre with the normal irradiance
``w_k E_sun``, ``w_k = a max(u_k . s, 0) cos e_k dA / (pi rho_k^2)``. A render with the
Sun in direction ``d_k`` and irradiance ``w_k E_sun`` gives that cell's share of the
target's intensity; the sum over ``k`` is the Earthshine intensity. The quadrature error
falls as the cells shrink: ``tests/illumination/test_illumination_earthshine.py`` checks
the irradiance on a nadir-facing plate above the subsolar point against the one-dimensional
integral of that geometry, and its far-field limit ``(2/3) a E_sun (R / D)^2`` (a Lambertian
sphere at zero phase).

The Earth's spectrum is grey (``a`` at every wavelength; a real Earth is bluer over ocean
and redder over land and vegetation) and its limb sharp (no atmosphere).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from speclight.constants import EARTH_MEAN_RADIUS_M

F64 = NDArray[np.float64]
GOLDEN_ANGLE_RAD = np.pi * (3.0 - np.sqrt(5.0))


def earthshine_sources(
    r_target_m: F64,
    sun_direction: F64,
    albedo: float,
    samples: int,
    radius_m: float = EARTH_MEAN_RADIUS_M,
) -> tuple[F64, F64]:
    """Directions and weights of the Earthshine sources seen from each target position.

    Parameters
    ----------
    r_target_m
        (N, 3) target positions from the Earth's centre [m] (any Earth-centred frame).
    sun_direction
        (N, 3) unit vectors toward the Sun, same frame (the Sun is far: one direction for
        the whole Earth).
    albedo
        The Earth's Lambertian albedo [1].
    samples
        Cells ``K`` of the visible cap.
    radius_m
        The Earth's radius [m].

    Returns
    -------
    directions : ndarray
        (N, K, 3) unit vectors from the target toward the cells' centres, same frame.
    weights : ndarray
        (N, K) each cell's normal irradiance over the solar irradiance [1] (0 for cells in
        the night); NaN rows where the target is not above the surface.
    """
    t = np.asarray(r_target_m, dtype=np.float64)
    s = np.asarray(sun_direction, dtype=np.float64)
    s = s / np.linalg.norm(s, axis=-1, keepdims=True)
    dist = np.linalg.norm(t, axis=-1)
    above = dist > radius_m
    z = t / np.where(above, dist, 1.0)[:, None]
    e1, e2 = _frame(z)
    k = np.arange(samples)
    cos_max = np.where(above, radius_m / np.where(above, dist, 1.0), 1.0)  # cap edge (N,)
    # equal-area cells: cos(theta) at the middle of K equal steps from 1 down to cos_max
    cos_th = 1.0 - (k[None, :] + 0.5) / samples * (1.0 - cos_max[:, None])  # (N, K)
    sin_th = np.sqrt(np.clip(1.0 - cos_th**2, 0.0, None))
    phi = k * GOLDEN_ANGLE_RAD
    u = (
        cos_th[..., None] * z[:, None, :]
        + (sin_th * np.cos(phi))[..., None] * e1[:, None, :]
        + (sin_th * np.sin(phi))[..., None] * e2[:, None, :]
    )  # (N, K, 3) unit normals of the cells
    to_cell = radius_m * u - t[:, None, :]
    rho = np.linalg.norm(to_cell, axis=-1)
    directions = to_cell / rho[..., None]
    cos_emit = np.clip(-np.einsum("nkc,nkc->nk", u, directions), 0.0, None)
    lit = np.clip(np.einsum("nkc,nc->nk", u, s), 0.0, None)
    area = 2.0 * np.pi * radius_m**2 * (1.0 - cos_max) / samples  # (N,)
    weights = albedo * lit * cos_emit * area[:, None] / (np.pi * rho**2)
    weights[~above] = np.nan
    return directions, weights


def _frame(z: F64) -> tuple[F64, F64]:
    """Two unit vectors completing ``z`` (N, 3) to a right-handed orthonormal frame."""
    helper = np.where(np.abs(z[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    e1 = np.cross(z, helper)
    e1 /= np.linalg.norm(e1, axis=-1, keepdims=True)
    return e1, np.cross(z, e1)
