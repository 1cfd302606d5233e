"""Orthographic view of the target along the line of sight."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]


def image_axes(observer_dir: F64) -> tuple[F64, F64]:
    """Right and up unit vectors (B, 3) of images seen from ``observer_dir`` (B, 3).

    Up is the body +z axis projected on the image plane (+y when looking along z); right is
    ``up x observer_dir`` so that (right, up, towards observer) is right-handed.
    """
    o = observer_dir
    ref = np.where((np.abs(o[:, 2]) > 0.999)[:, None], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0])
    up = ref - np.einsum("bk,bk->b", ref, o)[:, None] * o
    up /= np.linalg.norm(up, axis=1, keepdims=True)
    right = np.cross(up, o)
    return right, up


def pixel_grid(resolution_px: int, half_width_m: float) -> tuple[F64, F64]:
    """Pixel-centre coordinates x (right) and y (up) [m], (P,) each, row-major from the top."""
    c = (np.arange(resolution_px) + 0.5) / resolution_px * 2.0 - 1.0
    y, x = np.meshgrid(-c * half_width_m, c * half_width_m, indexing="ij")
    return x.ravel(), y.ravel()


def primary_rays(
    centre: F64, radius_m: float, observer_dir: F64, resolution_px: int
) -> tuple[F64, F64, float]:
    """Ray origins and directions (B*P, 3) of a batch of epochs, and the pixel area [m²].

    Rays start outside the bounding sphere (centre, radius) and travel towards -observer_dir.
    """
    right, up = image_axes(observer_dir)
    x, y = pixel_grid(resolution_px, radius_m)
    origin = (
        centre[None, None, :]
        + x[None, :, None] * right[:, None, :]
        + y[None, :, None] * up[:, None, :]
        + 2.0 * radius_m * observer_dir[:, None, :]
    )
    direction = np.broadcast_to(-observer_dir[:, None, :], origin.shape)
    pixel_area = (2.0 * radius_m / resolution_px) ** 2
    return origin.reshape(-1, 3), np.ascontiguousarray(direction.reshape(-1, 3)), pixel_area
