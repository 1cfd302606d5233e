"""The convex polyhedron of an EGI (the Minkowski problem), written as OBJ.

Given outward normals ``n_k`` and areas ``A_k`` with ``sum A_k n_k = 0``, the polyhedron
``{x : n_k . x <= h_k}`` whose facet areas are ``A_k`` exists and is unique up to translation
(Minkowski 1897). Little's method (Little 1983, Proc. IEEE CVPR, 247; Kaasalainen & Torppa
2001, Icarus 153, 24, sec. 2.2): the support distances ``h`` minimise ``sum A_k h_k`` at fixed
volume; with ``dV/dh_k = a_k(h)`` (the facet's present area) the minimum of the
scale-free ``F(h) = sum A_k h_k / V(h)^(1/3)`` has ``a_k(h) proportional to A_k``.
``F`` is minimised by L-BFGS-B (``h > 0``: the origin inside) with the analytic gradient
``A / V^(1/3) - F a(h) / (3 V)``; the result is scaled to the EGI's total area. The
polyhedron at each ``h`` comes from :class:`scipy.spatial.HalfspaceIntersection` and
:class:`scipy.spatial.ConvexHull`. Facets that vanish (``a_k = 0``) are allowed.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import minimize
from scipy.spatial import ConvexHull, HalfspaceIntersection

from speclight.estimate.shape.egi import close_egi

F64 = NDArray[np.float64]
MAX_ITERATIONS = 500


@dataclass(frozen=True)
class Polyhedron:
    """A convex polyhedron as a triangle mesh.

    Attributes
    ----------
    vertices
        (V, 3) vertex positions [the EGI's length unit].
    faces
        (F, 3) vertex indices, counter-clockwise seen from outside.
    facet_area
        (K,) area of each EGI facet on the polyhedron.
    support
        (K,) support distances ``h_k``.
    """

    vertices: F64
    faces: NDArray[np.int64]
    facet_area: F64
    support: F64


def polyhedron(normals: F64, support: F64) -> Polyhedron:
    """The polyhedron ``{x : n_k . x <= h_k}`` (origin inside: ``h > 0``)."""
    halfspaces = np.hstack([normals, -support[:, None]])
    verts = HalfspaceIntersection(halfspaces, np.zeros(3)).intersections
    hull = ConvexHull(verts)
    tri = hull.points[hull.simplices]
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    flip = np.sum(cross * hull.equations[:, :3], axis=1) < 0
    faces = np.where(flip[:, None], hull.simplices[:, ::-1], hull.simplices)
    area = 0.5 * np.linalg.norm(cross, axis=1)
    owner = np.argmax(hull.equations[:, :3] @ normals.T, axis=1)
    facet_area = np.bincount(owner, weights=area, minlength=len(normals)).astype(float)
    return Polyhedron(np.asarray(hull.points), faces.astype(np.int64), facet_area, support)


def minkowski_polyhedron(normals: F64, areas: F64) -> Polyhedron:
    """Solve the Minkowski problem for the EGI ``(normals, areas)`` (module doc). A
    non-closed EGI is closed first (:func:`speclight.estimate.shape.egi.close_egi`)."""
    target = close_egi(np.asarray(areas, float), normals)
    target = target / np.sum(target)

    def objective(h: F64) -> tuple[float, F64]:
        poly = polyhedron(normals, h)
        vol = ConvexHull(poly.vertices).volume
        f = float(target @ h) / vol ** (1.0 / 3.0)
        grad = target / vol ** (1.0 / 3.0) - f * poly.facet_area / (3.0 * vol)
        return f, grad

    h0 = np.ones(len(normals))
    res = minimize(
        objective,
        h0,
        jac=True,
        method="L-BFGS-B",
        bounds=[(1e-6, None)] * len(normals),
        options={"maxiter": MAX_ITERATIONS, "gtol": 1e-9, "ftol": 1e-11},
    )
    poly = polyhedron(normals, res.x)
    scale = np.sqrt(np.sum(areas) / np.sum(poly.facet_area))
    return Polyhedron(
        poly.vertices * scale, poly.faces, poly.facet_area * scale**2, poly.support * scale
    )


def format_obj(poly: Polyhedron, comment: str = "") -> str:
    """Wavefront OBJ text of the polyhedron (``v`` and 1-based ``f`` lines)."""
    lines = [f"# {line}" for line in comment.splitlines()]
    lines += [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in poly.vertices]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in poly.faces]
    return "\n".join(lines) + "\n"


def write_obj(path: str | Path, poly: Polyhedron, comment: str = "") -> Path:
    """Write :func:`format_obj` to ``path``; returns the path."""
    p = Path(path)
    p.write_text(format_obj(poly, comment))
    return p
