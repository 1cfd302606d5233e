"""Built-in target shapes: sphere, plate, cube, cylinder (rocket body), box-wing, bus with array.

Every builder returns a :class:`~speclight.target.parts.Target` in the body frame [m] and
takes ``materials``: one :class:`Material` for all parts or a mapping part name -> material.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.target.materials import Material
from speclight.target.parts import Part, Target, assign_materials

Materials = Material | Mapping[str, Material]
Mesh = tuple[NDArray[np.float64], NDArray[np.int64]]
CUBE_FACES: tuple[str, ...] = ("+x", "-x", "+y", "-y", "+z", "-z")


def _positive(name: str, value: float) -> float:
    v = float(value)
    if not (np.isfinite(v) and v > 0):
        raise InputError(f"{name} = {value!r} must be a finite number > 0", field=f"shape.{name}")
    return v


def _quad(p0, p1, p2, p3) -> Mesh:  # type: ignore[no-untyped-def]
    """Two triangles of the quad p0 p1 p2 p3 (counter-clockwise seen from the front)."""
    return np.array([p0, p1, p2, p3], dtype=float), np.array([[0, 1, 2], [0, 2, 3]])


def _merge(meshes: list[Mesh]) -> Mesh:
    verts, faces, off = [], [], 0
    for v, f in meshes:
        verts.append(v)
        faces.append(f + off)
        off += len(v)
    return np.vstack(verts), np.vstack(faces)


def _build(meshes: dict[str, Mesh], materials: Materials) -> Target:
    mats = assign_materials(list(meshes), materials)
    return Target(tuple(Part(n, v, f, mats[n]) for n, (v, f) in meshes.items()))


def uv_sphere_mesh(radius_m: float, n_lat: int = 24, n_lon: int = 48) -> Mesh:
    """Latitude-longitude triangulation of a sphere [m] with outward orientation."""
    theta = np.linspace(0.0, np.pi, n_lat + 1)[1:-1]
    phi = np.linspace(0.0, 2 * np.pi, n_lon, endpoint=False)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    ring = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1).reshape(-1, 3)
    v = np.vstack([[0, 0, 1], ring, [0, 0, -1]]) * radius_m
    idx = lambda i, j: 1 + i * n_lon + (j % n_lon)  # noqa: E731
    f = [[0, idx(0, j), idx(0, j + 1)] for j in range(n_lon)]
    for i in range(n_lat - 2):
        for j in range(n_lon):
            a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
            f += [[a, b, c], [a, c, d]]
    south = len(v) - 1
    f += [[south, idx(n_lat - 2, j + 1), idx(n_lat - 2, j)] for j in range(n_lon)]
    return v, np.array(f)


def sphere(radius_m: float, materials: Materials) -> Target:
    """Sphere of ``radius_m`` [m] centred on the origin, one part ``body``, traced exactly."""
    r = _positive("radius_m", radius_m)
    mats = assign_materials(["body"], materials)
    v, f = uv_sphere_mesh(r)
    return Target((Part("body", v, f, mats["body"], sphere_radius_m=r),))


def plate(width_m: float, height_m: float, materials: Materials) -> Target:
    """Flat rectangle in the x-y plane (width along x, height along y), normal +z, part ``plate``.

    The plate is a thin sheet: both faces reflect with the same material.
    """
    w, h = _positive("width_m", width_m) / 2, _positive("height_m", height_m) / 2
    return _build({"plate": _quad((-w, -h, 0), (w, -h, 0), (w, h, 0), (-w, h, 0))}, materials)


def _box_faces(half: NDArray[np.float64], centre: NDArray[np.float64]) -> dict[str, Mesh]:
    out: dict[str, Mesh] = {}
    for axis in range(3):
        for sign, label in ((1.0, "+"), (-1.0, "-")):
            u, w = (axis + 1) % 3, (axis + 2) % 3
            corners = []
            for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = np.zeros(3)
                p[axis] = sign * half[axis]
                p[u] = a * half[u] * sign
                p[w] = b * half[w]
                corners.append(centre + p)
            out[label + "xyz"[axis]] = _quad(*corners)
    return out


def cube(edge_m: float, materials: Materials) -> Target:
    """Cube of edge ``edge_m`` [m] centred on the origin; parts ``+x -x +y -y +z -z``."""
    e = _positive("edge_m", edge_m) / 2
    faces = _box_faces(np.full(3, e), np.zeros(3))
    return _build({k: faces[k] for k in CUBE_FACES}, materials)


def cylinder(radius_m: float, length_m: float, materials: Materials, segments: int = 96) -> Target:
    """Closed cylinder (rocket body) along z centred on the origin; parts ``side top bottom``."""
    r, h = _positive("radius_m", radius_m), _positive("length_m", length_m) / 2
    phi = np.linspace(0, 2 * np.pi, segments, endpoint=False)
    ring = np.stack([r * np.cos(phi), r * np.sin(phi)], -1)
    n = segments
    side_v = np.vstack([np.c_[ring, np.full(n, -h)], np.c_[ring, np.full(n, h)]])
    side_f = np.array(
        [[[j, (j + 1) % n, n + (j + 1) % n], [j, n + (j + 1) % n, n + j]] for j in range(n)]
    )
    top_v = np.vstack([[0, 0, h], np.c_[ring, np.full(n, h)]])
    top_f = np.array([[0, 1 + j, 1 + (j + 1) % n] for j in range(n)])
    bot_v = np.vstack([[0, 0, -h], np.c_[ring, np.full(n, -h)]])
    bot_f = np.array([[0, 1 + (j + 1) % n, 1 + j] for j in range(n)])
    return _build(
        {"side": (side_v, side_f.reshape(-1, 3)), "top": (top_v, top_f), "bottom": (bot_v, bot_f)},
        materials,
    )


def box_wing(
    materials: Materials,
    bus_size_m: tuple[float, float, float] = (1.0, 1.0, 1.5),
    wing_span_m: float = 3.0,
    wing_width_m: float = 1.2,
    wing_gap_m: float = 0.2,
    dish_radius_m: float = 0.4,
    dish_depth_m: float = 0.1,
    dish: bool = True,
) -> Target:
    """Box-wing satellite: bus, two solar wings and (unless ``dish`` is False) a parabolic
    antenna dish. All sizes in metres, body frame (docs/scenario.md, "The box-wing").

    * ``bus``: a box of edges ``bus_size_m`` (x, y, z) centred on the origin.
    * ``wing_+y``, ``wing_-y``: flat rectangles in the body y-z plane (x = 0), normal +x as
      built (both; every surface reflects on both sides), ``wing_span_m`` long along y and
      ``wing_width_m`` wide along z, centred on z = 0, from ``wing_gap_m`` beyond the bus's
      ±y face outwards: |y| from ``bus_y / 2 + gap`` to ``bus_y / 2 + gap + span``. Wing and
      bus face form concave corners. A wing turning about y (``target.articulation``, axis
      ``[0, 1, 0]``, normal ``[1, 0, 0]``) tracks the Sun.
    * ``antenna``: a paraboloid dish of radius ``dish_radius_m`` (aperture plane) and depth
      ``dish_depth_m`` on the body z axis below the bus: ``z = z0 + depth (1 - (rho / R)^2)``
      with ``z0 = -bus_z / 2 - depth - 1 mm``, so its apex is 1 mm below the bus's -z face
      and it opens towards -z (nadir when body +z points up). 8 rings of 32 sectors.

    Parameters
    ----------
    materials
        One material for every part, or part name -> material (``"*"`` for the rest).
    bus_size_m, wing_span_m, wing_width_m, wing_gap_m, dish_radius_m, dish_depth_m
        The sizes above [m].
    dish
        False: no ``antenna`` part (``dish_radius_m`` and ``dish_depth_m`` are then unused).
    """
    half = np.array([_positive("bus_size_m", s) for s in bus_size_m]) / 2
    span, width = _positive("wing_span_m", wing_span_m), _positive("wing_width_m", wing_width_m) / 2
    gap = float(wing_gap_m)
    bus = _merge(list(_box_faces(half, np.zeros(3)).values()))
    y0, y1 = half[1] + gap, half[1] + gap + span
    wp = _quad((0, y0, -width), (0, y1, -width), (0, y1, width), (0, y0, width))
    wm = _quad((0, -y0, width), (0, -y1, width), (0, -y1, -width), (0, -y0, -width))
    meshes = {"bus": bus, "wing_+y": wp, "wing_-y": wm}
    if dish:
        meshes["antenna"] = _dish(
            _positive("dish_radius_m", dish_radius_m),
            _positive("dish_depth_m", dish_depth_m),
            -half[2],
        )
    return _build(meshes, materials)


def _dish(R: float, d: float, z_bottom: float) -> Mesh:
    """Paraboloid dish z = z0 + d (1 - (rho / R)^2) opening towards -z, apex 1 mm below
    ``z_bottom`` (the bus's -z face)."""
    nr, nphi = 8, 32
    rho = np.linspace(0, R, nr + 1)[1:]
    phi = np.linspace(0, 2 * np.pi, nphi, endpoint=False)
    rr, pp = np.meshgrid(rho, phi, indexing="ij")
    z0 = z_bottom - d - 1e-3
    ring = np.stack([rr * np.cos(pp), rr * np.sin(pp), z0 + d * (1 - (rr / R) ** 2)], -1)
    dv = np.vstack([[0, 0, z0 + d], ring.reshape(-1, 3)])
    idx = lambda i, j: 1 + i * nphi + (j % nphi)  # noqa: E731
    df = [[0, idx(0, j + 1), idx(0, j)] for j in range(nphi)]
    for i in range(nr - 1):
        for j in range(nphi):
            df += [
                [idx(i, j), idx(i, j + 1), idx(i + 1, j + 1)],
                [idx(i, j), idx(i + 1, j + 1), idx(i + 1, j)],
            ]
    return dv, np.array(df)


def bus_array(
    materials: Materials,
    bus_size_m: tuple[float, float, float] = (2.8, 1.3, 0.3),
    array_size_m: tuple[float, float] = (8.1, 2.8),
    array_gap_m: float = 0.2,
    array_offset_m: float = 0.0,
) -> Target:
    """A flat bus with one solar array above it (Starlink-like, for nadir pointing).

    The bus is a box centred on the origin; its +z face (part ``bus_nadir``, the chassis
    underside when body +z points to nadir) is the face Fankhauser, Askari & Tyson 2023 model,
    the other five faces are part ``bus``. The array (part ``array``) is a plate
    perpendicular to the bus, in the plane x = ``array_offset_m`` parallel to y-z (normal
    +x, length ``array_size_m[0]`` along y, height ``array_size_m[1]`` along z), on the -z
    (zenith) side ``array_gap_m`` above the bus, centred on y = 0. With the default offset 0
    it stands on the z axis: turning it about z (``target.articulation``) keeps it
    perpendicular to the bus and clear of it. ``array_offset_m = -bus_size_m[0] / 2`` and
    ``array_gap_m = 0`` hinge it on the bus's top -x edge, an L whose +x (normal) side looks
    over the bus. The defaults give the Starlink v1.5 areas: bus underside 2.8 x 1.3 =
    3.64 m², array 8.1 x 2.8 = 22.68 m².
    """
    half = np.array([_positive("bus_size_m", s) for s in bus_size_m]) / 2
    length, height = (_positive("array_size_m", s) for s in array_size_m)
    gap = float(array_gap_m)
    if not (np.isfinite(gap) and gap >= 0):
        raise InputError(f"array_gap_m = {array_gap_m!r} must be >= 0", field="shape.array_gap_m")
    x = float(array_offset_m)
    if not np.isfinite(x):
        raise InputError(
            f"array_offset_m = {array_offset_m!r} must be a finite number",
            field="shape.array_offset_m",
        )
    faces = _box_faces(half, np.zeros(3))
    nadir = faces.pop("+z")
    z0, z1, y = -half[2] - gap, -half[2] - gap - height, length / 2
    arr = _quad((x, y, z0), (x, -y, z0), (x, -y, z1), (x, y, z1))
    meshes = {"bus_nadir": nadir, "bus": _merge(list(faces.values())), "array": arr}
    return _build(meshes, materials)
