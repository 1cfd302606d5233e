"""What the mesh readers share: the mesh type, the scenario field they report, triangle fans."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError

#: Vertices (V, 3) [file units] and triangles (F, 3) as vertex indices.
Mesh = tuple[NDArray[np.float64], NDArray[np.int64]]
FIELD = "target.shape.mesh_file"


def fan(poly: list[int]) -> list[list[int]]:
    """Split a polygon (vertex indices) into a triangle fan around its first vertex."""
    return [[poly[0], poly[k], poly[k + 1]] for k in range(1, len(poly) - 1)]


def mesh_error(path: Path, message: str) -> InputError:
    """An input error about the mesh file ``path``."""
    return InputError(message, source=str(path), field=FIELD)
