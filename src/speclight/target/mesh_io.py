"""Read target meshes: Wavefront OBJ (groups/objects become parts) and PLY (one part per file).

OBJ: Wavefront Technologies, "Object Files (.obj)", Advanced Visualizer manual, appendix B.
PLY: Turk 1994, "The PLY polygon file format" (Stanford). Coordinates are taken as metres
times ``scale_m_per_unit``; polygons are split into triangle fans.

Every malformed file is an :class:`InputError` naming the file and, where it helps, the
line. Faces of zero area (repeated or collinear vertices) are dropped with a warning that
counts them; a part with no face of positive area, a non-finite coordinate, or a target whose
bounding radius after ``scale_m_per_unit`` is outside :data:`MIN_BOUNDING_RADIUS_M` ..
:data:`MAX_BOUNDING_RADIUS_M` is refused with the reason.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.input_files import read_user_bytes
from speclight.target.materials import Material
from speclight.target.parts import Part, Target, assign_materials

Mesh = tuple[NDArray[np.float64], NDArray[np.int64]]
FIELD = "target.shape.mesh_file"
#: Accepted bounding radius of a mesh target after ``scale_m_per_unit`` [m]: from a 1 mm
#: fragment to 100 km (the largest space object, the ISS, spans about 110 m), so that a
#: wrong unit (1000x, 1e12x) is caught before the renderer sees it.
MIN_BOUNDING_RADIUS_M = 1e-3
MAX_BOUNDING_RADIUS_M = 1e5
#: A face whose area is below (float32 eps x the part's bounding radius)^2 has zero area: the
#: renderer's single-precision geometry cannot resolve it (repeated or collinear vertices).
_ZERO_AREA_FRACTION = float(np.finfo(np.float32).eps) ** 2

_PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
    "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}  # fmt: skip
_PLY_FORMATS = ("ascii", "binary_little_endian", "binary_big_endian")
_NUMBER = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?|[-+]?(nan|inf|infinity)", re.I)


@dataclass
class _PlyProperty:
    """One property: name, numpy type code, and the count type code if it is a list."""

    name: str
    dtype: str
    count_dtype: str | None = None


@dataclass
class _PlyElement:
    name: str
    count: int
    props: list[_PlyProperty] = field(default_factory=list)


def _fan(poly: list[int]) -> list[list[int]]:
    return [[poly[0], poly[k], poly[k + 1]] for k in range(1, len(poly) - 1)]


def _fail(path: Path, message: str) -> InputError:
    return InputError(message, source=str(path), field=FIELD)


def read_obj(path: Path) -> dict[str, Mesh]:
    """Parts of an OBJ file: name -> (vertices (V, 3), faces (F, 3)), compacted per part."""
    verts: list[list[float]] = []
    faces: dict[str, list[list[int]]] = {}
    current = path.stem
    text = read_user_bytes(path, FIELD).decode("utf-8", errors="replace")
    for lineno, raw in enumerate(text.splitlines(), 1):
        tok = raw.split("#", 1)[0].split()
        if not tok:
            continue
        try:
            if tok[0] == "v":
                verts.append([float(x) for x in tok[1:4]])
                if len(verts[-1]) != 3:
                    raise ValueError("a vertex needs x y z")
            elif tok[0] in ("g", "o"):
                current = " ".join(tok[1:]) or path.stem
            elif tok[0] == "f":
                idx = []
                for t in tok[1:]:
                    i = int(t.split("/")[0])
                    idx.append(i - 1 if i > 0 else len(verts) + i)
                if len(idx) < 3:
                    raise ValueError("a face needs at least 3 vertices")
                faces.setdefault(current, []).extend(_fan(idx))
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


def _ply_type(path: Path, name: str, where: str) -> str:
    if name not in _PLY_TYPES:
        raise _fail(
            path, f"{where}: type '{name}' is not a PLY type (accepted: {', '.join(_PLY_TYPES)})"
        )
    return _PLY_TYPES[name]


def _ply_header(path: Path, data: bytes) -> tuple[str, list[_PlyElement], bytes, int]:
    """Format, elements, body bytes and the file line number where the body starts."""
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise _fail(path, "not a PLY file (no 'ply' magic or 'end_header')")
    newline = data.find(b"\n", end)
    body = b"" if newline < 0 else data[newline + 1 :]
    lines = data[:end].decode("ascii", errors="replace").splitlines()
    fmt = ""
    elements: list[_PlyElement] = []
    for lineno, line in enumerate(lines, 1):
        tok = line.split()
        where = f"line {lineno} {line.strip()!r}"
        if not tok or tok[0] in ("ply", "comment", "obj_info"):
            continue
        if tok[0] == "format" and len(tok) >= 2:
            fmt = tok[1]
        elif tok[0] == "element" and len(tok) == 3:
            if not tok[2].isdigit():
                raise _fail(path, f"{where}: the count '{tok[2]}' is not an integer >= 0")
            elements.append(_PlyElement(tok[1], int(tok[2])))
        elif tok[0] == "property" and not elements:
            raise _fail(path, f"{where}: a property before any element")
        elif tok[0] == "property" and len(tok) == 5 and tok[1] == "list":
            count_dt, item_dt = _ply_type(path, tok[2], where), _ply_type(path, tok[3], where)
            if count_dt[0] not in "iu" or (elements[-1].name == "face" and item_dt[0] not in "iu"):
                raise _fail(path, f"{where}: list counts and vertex indices must be integer types")
            elements[-1].props.append(_PlyProperty(tok[4], item_dt, count_dt))
        elif tok[0] == "property" and len(tok) == 3:
            elements[-1].props.append(_PlyProperty(tok[2], _ply_type(path, tok[1], where)))
        else:
            raise _fail(path, f"{where} is not a PLY header line (format, element, property)")
    if fmt not in _PLY_FORMATS:
        raise _fail(
            path, f"PLY format '{fmt}' is not supported (accepted: {', '.join(_PLY_FORMATS)})"
        )
    return fmt, elements, body, len(lines) + 2


def _ascii_row(props: list[_PlyProperty], tok: list[str]) -> list[Any] | None:
    """Values of one ASCII row, one per property (lists as lists); None if they do not fit."""
    pos, values = 0, list[Any]()
    try:
        for prop in props:
            convert = int if prop.dtype[0] in "iu" else float
            if prop.count_dtype is None:
                values.append(convert(tok[pos]))
                pos += 1
            else:
                n = int(tok[pos])
                items = tok[pos + 1 : pos + 1 + n]
                if len(items) != n:
                    return None
                values.append([convert(t) for t in items])
                pos += 1 + n
    except IndexError:
        return None
    return values if pos == len(tok) else None


def _ascii_rows(path: Path, el: _PlyElement, rows: list[tuple[int, str]]) -> list[list[Any]]:
    """Values of each row of an ASCII element, one entry per property."""
    out = []
    for lineno, text in rows:
        tok = text.split()
        try:
            values = _ascii_row(el.props, tok)
        except ValueError:
            bad = next((t for t in tok if _NUMBER.fullmatch(t) is None), None)
            what = f"{bad!r} is not a number" if bad else "an integer (count or index) is expected"
            raise _fail(path, f"line {lineno} {text!r}: {what}") from None
        if values is None:
            raise _fail(
                path,
                f"line {lineno} {text!r} has {len(tok)} values, which do not fit the header's "
                f"{el.name} properties ({', '.join(p.name for p in el.props)}; a list is its "
                "count, then that many values)",
            )
        out.append(values)
    return out


def _binary_rows(
    path: Path, el: _PlyElement, body: bytes, off: int, order: str
) -> tuple[dict[str, Any], int]:
    """Columns of a binary element (lists as a list of arrays) and the offset after it."""
    truncated = _fail(
        path,
        f"binary data is truncated: {len(body) - off} bytes are left for the {el.count} "
        f"{el.name} rows",
    )
    if not el.props:
        return {}, off
    if all(p.count_dtype is None for p in el.props):
        dt = np.dtype([(f"p{k}", order + p.dtype) for k, p in enumerate(el.props)])
        if off + dt.itemsize * el.count > len(body):
            raise truncated
        arr = np.frombuffer(body, dt, el.count, off)
        return {p.name: arr[f"p{k}"] for k, p in enumerate(el.props)}, off + dt.itemsize * el.count
    columns: dict[str, list[Any]] = {p.name: [] for p in el.props}
    for _ in range(el.count):
        for p in el.props:
            n, item = 1, np.dtype(order + p.dtype)
            if p.count_dtype is not None:
                counter = np.dtype(order + p.count_dtype)
                if off + counter.itemsize > len(body):
                    raise truncated
                n = int(np.frombuffer(body, counter, 1, off)[0])
                off += counter.itemsize
            if n < 0 or off + n * item.itemsize > len(body):
                raise truncated
            value = np.frombuffer(body, item, n, off)
            off += n * item.itemsize
            columns[p.name].append(value if p.count_dtype is not None else value[0])
    return columns, off


def read_ply(path: Path) -> Mesh:
    """Vertices and triangulated faces of an ASCII or binary PLY file.

    Raises
    ------
    InputError
        If the header is malformed (unknown type, a count that is not an integer, no x, y
        or z vertex property), the data do not match the header's counts (too few or too
        many rows, a truncated binary body), a value is not a number, or a face has fewer
        than 3 vertices or refers to a vertex that does not exist.
    """
    fmt, elements, body, first_line = _ply_header(path, read_user_bytes(path, FIELD))
    columns: dict[str, dict[str, Any]] = {}
    if fmt == "ascii":
        text = body.decode("ascii", errors="replace").splitlines()
        rows = [(first_line + k, r) for k, r in enumerate(text) if r.strip()]
        pos = 0
        for el in elements:
            if len(rows) - pos < el.count:
                raise _fail(
                    path,
                    f"the header announces {el.count} {el.name} rows but {len(rows) - pos} "
                    "data lines are left",
                )
            values = _ascii_rows(path, el, rows[pos : pos + el.count])
            columns[el.name] = {p.name: [r[k] for r in values] for k, p in enumerate(el.props)}
            pos += el.count
        if pos < len(rows):
            raise _fail(
                path,
                f"{len(rows) - pos} line(s) after the last element (from line {rows[pos][0]}): "
                "the header's element counts do not match the data",
            )
    else:
        order, off = ("<" if fmt == "binary_little_endian" else ">"), 0
        for el in elements:
            columns[el.name], off = _binary_rows(path, el, body, off, order)
        if body[off:].strip():
            raise _fail(
                path,
                f"{len(body) - off} bytes after the last element: the header's element counts "
                "do not match the data",
            )
    return _ply_mesh(path, elements, columns)


def _ply_mesh(path: Path, elements: list[_PlyElement], columns: dict[str, dict[str, Any]]) -> Mesh:
    """The (vertices, triangles) of parsed PLY elements, with the indices checked."""
    names = [el.name for el in elements]
    if "vertex" not in names or "face" not in names:
        raise _fail(path, "a PLY mesh needs a 'vertex' and a 'face' element")
    vertex = elements[names.index("vertex")]
    scalar = {p.name for p in vertex.props if p.count_dtype is None}
    for axis in "xyz":
        if axis not in scalar:
            raise _fail(path, f"the vertex element has no '{axis}' property (it needs x, y, z)")
    verts = np.stack([np.asarray(columns["vertex"][c], dtype=float) for c in "xyz"], axis=1)
    face = elements[names.index("face")]
    lists = [p.name for p in face.props if p.count_dtype is not None]
    if not lists:
        raise _fail(path, "the face element has no list property (vertex_indices)")
    key = next((n for n in ("vertex_indices", "vertex_index") if n in lists), lists[0])
    triangles: list[list[int]] = []
    for k, poly in enumerate(columns["face"][key]):
        idx = [int(i) for i in poly]
        if len(idx) < 3:
            raise _fail(path, f"face {k} has {len(idx)} vertices; a face needs at least 3")
        bad = [i for i in idx if not 0 <= i < len(verts)]
        if bad:
            raise _fail(
                path,
                f"face {k} refers to vertex {bad[0]}, but the file has {len(verts)} vertices "
                "(numbered from 0)",
            )
        triangles.extend(_fan(idx))
    if not triangles:
        raise _fail(path, "PLY file has no faces")
    return verts, np.asarray(triangles, dtype=np.int64)


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
    """Target from an OBJ file (each group/object is a part) or PLY files (one part each).

    Parameters
    ----------
    path
        One ``.obj`` or ``.ply`` file, or a list of ``.ply`` files (part name = file stem).
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
        ext = p.suffix.lower()
        if not p.exists():
            raise _fail(p, "mesh file not found")
        if ext == ".obj":
            found = read_obj(p)
        elif ext == ".ply":
            found = {p.stem: read_ply(p)}
        else:
            raise _fail(p, f"unsupported mesh format '{ext}' (accepted: .obj, .ply)")
        for name, (v, f) in found.items():
            with np.errstate(over="ignore"):  # a coordinate overflowing to inf is refused
                meshes[name] = _checked_part(name, v * scale_m_per_unit, f, p, scale_m_per_unit)
    source = ", ".join(str(p) for p in paths)
    mats = assign_materials(list(meshes), part_materials, source=source)
    target = Target(tuple(Part(n, v, f, mats[n]) for n, (v, f) in meshes.items()))
    _, radius = target.bounding_sphere()
    if radius < MIN_BOUNDING_RADIUS_M:
        reach = max(float(np.linalg.norm(p.vertices_m, axis=1).max()) for p in target.parts)
        raise _out_of_scale("the mesh", radius, reach, scale_m_per_unit, source)
    return target
