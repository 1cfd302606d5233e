"""Extended Gaussian images (EGI): facet normals on a HEALPix sphere and their areas.

A convex polyhedron is determined, up to translation, by its facets' outward normals and
areas (Minkowski 1897); light-curve inversion fits the areas for fixed normals (Kaasalainen &
Torppa 2001, Icarus 153, 24, sec. 2, doi:10.1006/icar.2001.6673). The normals here are the
centres of the ``12 nside^2`` HEALPix pixels (RING order; Gorski et al. 2005, ApJ 622, 759),
equal in solid angle; the areas are ``exp(g)`` of the fitted parameters ``g``, so they stay
positive. A closed body's EGI sums to zero, ``sum_k a_k n_k = 0``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError

F64 = NDArray[np.float64]
MAX_NSIDE = 16


def facet_normals(nside: int) -> F64:
    """(12 nside^2, 3) unit normals at the HEALPix pixel centres (RING order)."""
    from astropy_healpix import healpix_to_lonlat

    if not (
        isinstance(nside, int | np.integer) and 1 <= nside <= MAX_NSIDE and nside & (nside - 1) == 0
    ):
        raise InputError(f"nside = {nside} must be a power of 2 in [1, {MAX_NSIDE}]", field="nside")
    lon, lat = healpix_to_lonlat(np.arange(12 * nside * nside), nside, order="ring")
    lon_r, lat_r = np.asarray(lon.to_value("rad")), np.asarray(lat.to_value("rad"))
    return np.stack(
        [np.cos(lat_r) * np.cos(lon_r), np.cos(lat_r) * np.sin(lon_r), np.sin(lat_r)], axis=1
    )


def closure_vector(areas: F64, normals: F64) -> F64:
    """``sum_k a_k n_k / sum_k a_k``: zero for a closed body [1]."""
    return np.asarray(areas @ normals / np.sum(areas))


def close_egi(areas: F64, normals: F64, iterations: int = 20) -> F64:
    """The nearest closed EGI: areas ``a_k (1 + n_k . m)`` with ``m`` such that the sum of
    ``a_k n_k`` vanishes (a relative change smooth over the sphere; repeated where a factor
    went negative, clipped to zero there)."""
    a = np.asarray(areas, dtype=float).copy()
    for _ in range(iterations):
        s = a @ normals
        if np.linalg.norm(s) <= 1e-12 * np.sum(a):
            break
        m = np.linalg.solve((normals * a[:, None]).T @ normals, -s)
        a = np.clip(a * (1.0 + normals @ m), 0.0, None)
    return a


def mesh_egi(vertices_m: F64, faces: NDArray[np.int64], normals: F64) -> F64:
    """A triangle mesh's EGI on the facet ``normals``: each face's area [m2] added to the
    facet whose normal is nearest to the face's outward normal."""
    tri = np.asarray(vertices_m, dtype=float)[np.asarray(faces)]
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area = 0.5 * np.linalg.norm(cross, axis=1)
    keep = area > 0
    unit = cross[keep] / (2.0 * area[keep, None])
    nearest = np.argmax(unit @ normals.T, axis=1)
    return np.bincount(nearest, weights=area[keep], minlength=len(normals)).astype(float)


def smooth_egi(areas: F64, normals: F64, fwhm_deg: float) -> F64:
    """The EGI as an area density smoothed by a Gaussian of ``fwhm_deg`` on the sphere
    (normalised kernel: the total area is kept)."""
    sigma = np.deg2rad(fwhm_deg) / (2.0 * np.sqrt(2.0 * np.log(2.0)))
    ang = np.arccos(np.clip(normals @ normals.T, -1.0, 1.0))
    w = np.exp(-0.5 * (ang / sigma) ** 2)
    w /= w.sum(axis=0, keepdims=True)
    return np.asarray(w @ areas)


def egi_difference(areas: F64, reference: F64, normals: F64, fwhm_deg: float) -> float:
    """Half the L1 distance between two EGIs, each smoothed (:func:`smooth_egi`) and
    normalised to unit total area: 0 for the same distribution, 1 for disjoint ones."""
    p = smooth_egi(areas / np.sum(areas), normals, fwhm_deg)
    q = smooth_egi(reference / np.sum(reference), normals, fwhm_deg)
    return float(0.5 * np.sum(np.abs(p / p.sum() - q / q.sum())))


def _is_closed(vertices: F64, faces: NDArray[np.int64]) -> bool:
    """True when every edge of the mesh is shared by exactly two faces (vertices at the
    same place, to 1e-9 of the mesh's size, are one: faces built as separate quads)."""
    v = np.asarray(vertices, float)
    size = max(float(np.ptp(v)), 1e-300)
    _, same = np.unique(np.round(v / (1e-9 * size)), axis=0, return_inverse=True)
    f = same.ravel()[np.asarray(faces)]
    edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return bool(np.all(counts == 2))


def mesh_facets(parts: list[tuple[F64, NDArray[np.int64]]]) -> tuple[F64, F64]:
    """Face normals (F, 3) and areas (F,) [m2] of meshes ``(vertices_m, faces)``, as the
    render sees them: a closed mesh by its outward faces, an open one (a thin sheet,
    reflecting on both sides, :mod:`speclight.render.single`) by each face twice, once per
    side."""
    normals, areas = [], []
    for vertices, faces in parts:
        tri = np.asarray(vertices, float)[np.asarray(faces)]
        cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        area = 0.5 * np.linalg.norm(cross, axis=1)
        keep = area > 0
        unit = cross[keep] / (2.0 * area[keep, None])
        normals.append(unit)
        areas.append(area[keep])
        if not _is_closed(vertices, np.asarray(faces)):
            normals.append(-unit)
            areas.append(area[keep])
    return np.vstack(normals), np.concatenate(areas)


def spread_egi(normals: F64, areas: F64, fwhm_deg: float, nside: int) -> tuple[F64, F64]:
    """An EGI spread over the HEALPix facets of ``nside`` by a Gaussian of ``fwhm_deg`` on
    the sphere (each face's area shared among the facets near its normal, total kept):
    the light curve of a body with rounded edges, smoother in the attitude."""
    pix = facet_normals(nside)
    sigma = np.deg2rad(fwhm_deg) / (2.0 * np.sqrt(2.0 * np.log(2.0)))
    ang = np.arccos(np.clip(pix @ np.asarray(normals).T, -1.0, 1.0))
    w = np.exp(-0.5 * (ang / sigma) ** 2)
    w /= w.sum(axis=0, keepdims=True)
    return pix, np.asarray(w @ areas)
