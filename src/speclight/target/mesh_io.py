"""Read target meshes: OBJ (material groups, groups or objects become parts), PLY (one part
per file), STL and glTF (through trimesh, :mod:`speclight.target.mesh_trimesh`).

OBJ: Wavefront Technologies, "Object Files (.obj)", Advanced Visualizer manual, appendix B:
``usemtl NAME`` starts a part named NAME (the faces of one material), ``g``/``o`` a part
named for the group or object. PLY: Turk 1994, "The PLY polygon file format" (Stanford).
Coordinates are taken as metres times ``scale_m_per_unit``; polygons are split into triangle
fans.

Every malformed file is an :class:`InputError` naming the file and, where it helps, the
line. Faces of zero area (repeated or collinear vertices) are dropped with a warning that
counts them; a part with no face of positive area, a non-finite coordinate, or a target whose
bounding radius after ``scale_m_per_unit`` is outside :data:`MIN_BOUNDING_RADIUS_M` ..
:data:`MAX_BOUNDING_RADIUS_M` is refused with the reason.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.input_files import read_user_bytes
from speclight.plausible_ranges import TARGET_SIZE_M, warn_implausible
from speclight.target.materials import Material
from speclight.target.mesh_common import FIELD, Mesh, fan
from speclight.target.mesh_common import mesh_error as _fail
from speclight.target.mesh_trimesh import TRIMESH_SUFFIXES, read_trimesh
from speclight.target.parts import Part, Target, assign_materials
from speclight.target.ply import read_ply

#: Accepted bounding radius of a mesh target after ``scale_m_per_unit`` [m]: from a 1 mm
#: fragment to 100 km (the largest space object, the ISS, spans about 110 m), so that a
#: wrong unit (1000x, 1e12x) is caught before the renderer sees it.
MIN_BOUNDING_RADIUS_M = 1e-3
MAX_BOUNDING_RADIUS_M = 1e5
#: A face whose area is below (float32 eps x the part's bounding radius)^2 has zero area: the
#: renderer's single-precision geometry cannot resolve it (repeated or collinear vertices).
_ZERO_AREA_FRACTION = float(np.finfo(np.float32).eps) ** 2


def read_obj(path: Path) -> dict[str, Mesh]:
    """Parts of an OBJ file: name -> (vertices (V, 3), faces (F, 3)), compacted per part."""
    verts: list[list[float]] = []
    faces: dict[str, list[list[int]]] = {}
    current = path.stem
    text = read_user_bytes(path, FIELD).decode("utf-8", errors="replace")
    for lineno, raw in enumerate(text.splitlines(), 1):
        tok = raw.split("#", 1)[0].split()
        try:
            current = _obj_line(tok, verts, faces, current, path.stem)
        except ValueError as exc:
            raise _fail(path, f"line {lineno} {raw.strip()!r}: {exc}") from None
    if not faces:
        raise _fail(path, "no faces found (need 'f' lines)")
    v = np.asarray(verts, dtype=float).reshape(-1, 3)
    out = {}
    for name, f in faces.items():
        fa = np.asarray(f, dtype=np.int64)
        if fa.min() < 0 or fa.max() >= len(v):
            raise _fail(path, f"part '{name}' refers to a vertex that does not exist")
        used, inverse = np.unique(fa, return_inverse=True)
        out[name] = (v[used], inverse.reshape(-1, 3))
    return out


def _obj_line(
    tok: list[str],
    verts: list[list[float]],
    faces: dict[str, list[list[int]]],
    current: str,
    stem: str,
) -> str:
    """Read one OBJ line's fields ``tok`` into ``verts`` / ``faces``; the part that
    follows (``g``, ``o``, ``usemtl`` start one; ``stem``: the file's, for a nameless one)."""
    if not tok:
        return current
    if tok[0] == "v":
        verts.append([float(x) for x in tok[1:4]])
        if len(verts[-1]) != 3:
            raise ValueError("a vertex needs x y z")
    elif tok[0] in ("g", "o", "usemtl"):
        return " ".join(tok[1:]) or stem
    elif tok[0] == "f":
        faces.setdefault(current, []).extend(fan(_face_indices(tok[1:], len(verts))))
    return current


def _face_indices(fields: list[str], n_verts: int) -> list[int]:
    """0-based vertex indices of an ``f`` line's fields (``v``, ``v/vt``, ``v/vt/vn``;
    negative: counted back from the last vertex read)."""
    idx = []
    for t in fields:
        i = int(t.split("/")[0])
        idx.append(i - 1 if i > 0 else n_verts + i)
    if len(idx) < 3:
        raise ValueError("a face needs at least 3 vertices")
    return idx


def _out_of_scale(what: str, radius: float, reach: float, scale: float, src: str) -> InputError:
    lo, hi = MIN_BOUNDING_RADIUS_M, MAX_BOUNDING_RADIUS_M
    return InputError(
        f"{what} has a bounding radius {radius:.3g} m and reaches {reach:.3g} m from the body "
        f"origin (scale_m_per_unit = {scale:g}); accepted: {lo:g} to {hi:g} m of bounding "
        f"radius, every vertex within {hi:g} m of the origin. Check scale_m_per_unit (metres "
        "per file unit: 0.001 for a file in mm)",
        source=src,
        field=FIELD,
    )


def _longest(vectors: NDArray[np.float64]) -> float:
    """The largest Euclidean norm of (n, 3) vectors, without overflow (coordinates ~1e300)."""
    big = float(np.abs(vectors).max())
    return big * float(np.linalg.norm(vectors / big, axis=1).max()) if big > 0 else 0.0


def _checked_part(
    name: str, v: NDArray[np.float64], f: NDArray[np.int64], path: Path, scale: float
) -> Mesh:
    """A part (vertices in m) without its zero-area faces, compacted; or why it is refused."""
    used = v[np.unique(f)]
    if not np.all(np.isfinite(used)):
        bad = int((~np.isfinite(used)).sum())
        raise _fail(path, f"part '{name}' has {bad} vertex coordinates that are not finite")
    radius = _longest(used - (0.5 * used.min(0) + 0.5 * used.max(0)))
    reach = _longest(used)
    if not (radius <= MAX_BOUNDING_RADIUS_M and reach <= MAX_BOUNDING_RADIUS_M):
        raise _out_of_scale(f"part '{name}'", radius, reach, scale, str(path))
    t = v[f]
    twice_area = np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1)
    good = twice_area > 2.0 * _ZERO_AREA_FRACTION * radius**2
    if not good.any():
        raise _fail(
            path,
            f"part '{name}' has no face of positive area (all its {len(f)} face(s) have "
            "repeated or collinear vertices)",
        )
    if not good.all():
        warnings.warn(
            f"{path}: part '{name}': dropped {int((~good).sum())} of {len(f)} faces of zero "
            "area (repeated or collinear vertices)",
            UserWarning,
            stacklevel=3,
        )
    kept, inverse = np.unique(f[good], return_inverse=True)
    return v[kept], inverse.reshape(-1, 3)


def load_mesh(
    path: str | Path | Sequence[str | Path],
    part_materials: Material | Mapping[str, Material],
    *,
    scale_m_per_unit: float = 1.0,
) -> Target:
    """Target from a mesh file (OBJ, STL, glTF: parts as the module says) or PLY files.

    Parameters
    ----------
    path
        One ``.obj``, ``.stl``, ``.gltf``, ``.glb`` or ``.ply`` file, or a list of files
        (a ``.ply`` or ``.stl`` part is named for its file stem).
    part_materials
        One material for all parts or a mapping part name -> material (``"*"``: the rest).
        Naming a part that the file lacks is an :class:`InputError` listing the parts found.
    scale_m_per_unit
        Metres per file unit [m].

    Raises
    ------
    InputError
        If a file is missing or malformed (see :func:`read_ply`), a part has no face of
        positive area or a non-finite coordinate, or the bounding radius is outside
        :data:`MIN_BOUNDING_RADIUS_M` .. :data:`MAX_BOUNDING_RADIUS_M`.
    """
    if not (np.isfinite(scale_m_per_unit) and scale_m_per_unit > 0):
        raise InputError(
            f"scale_m_per_unit = {scale_m_per_unit!r} must be a finite number > 0 (metres per "
            "file unit)",
            source=", ".join(map(str, [path] if isinstance(path, str | Path) else path)),
            field="target.shape.scale_m_per_unit",
        )
    paths = [Path(path)] if isinstance(path, str | Path) else [Path(p) for p in path]
    meshes: dict[str, Mesh] = {}
    for p in paths:
        for name, (v, f) in _read_parts(p).items():
            with np.errstate(over="ignore"):  # a coordinate overflowing to inf is refused
                meshes[name] = _checked_part(name, v * scale_m_per_unit, f, p, scale_m_per_unit)
    source = ", ".join(str(p) for p in paths)
    mats = assign_materials(list(meshes), part_materials, source=source)
    target = Target(tuple(Part(n, v, f, mats[n]) for n, (v, f) in meshes.items()))
    _check_size(target, scale_m_per_unit, source)
    return target


def _read_parts(p: Path) -> dict[str, Mesh]:
    """The parts of one mesh file, read by its format (the file's suffix)."""
    ext = p.suffix.lower()
    if not p.exists():
        raise _fail(p, "mesh file not found")
    if ext == ".obj":
        return read_obj(p)
    if ext == ".ply":
        return {p.stem: read_ply(p)}
    if ext in TRIMESH_SUFFIXES:
        return read_trimesh(p)
    accepted = ", ".join((".obj", ".ply", *TRIMESH_SUFFIXES))
    raise _fail(p, f"unsupported mesh format '{ext}' (accepted: {accepted})")


def _check_size(target: Target, scale_m_per_unit: float, source: str) -> None:
    """Refuse a target below :data:`MIN_BOUNDING_RADIUS_M`; warn about an implausible one."""
    _, radius = target.bounding_sphere()
    if radius < MIN_BOUNDING_RADIUS_M:
        reach = max(float(np.linalg.norm(p.vertices_m, axis=1).max()) for p in target.parts)
        raise _out_of_scale("the mesh", radius, reach, scale_m_per_unit, source)
    size = f"{FIELD} (its bounding diameter with scale_m_per_unit = {scale_m_per_unit:g})"
    warn_implausible(size, 2.0 * radius, TARGET_SIZE_M)
