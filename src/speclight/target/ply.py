"""Read PLY meshes, ASCII and binary (one part per file).

Reference: Turk 1994, "The PLY polygon file format" (Stanford). Polygons are split into
triangle fans. Every malformed file is an :class:`~speclight.errors.InputError` naming the
file and, where it helps, the line.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from speclight.input_files import read_user_bytes
from speclight.target.mesh_common import FIELD, Mesh, fan
from speclight.target.mesh_common import mesh_error as _fail

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
        fmt = _header_line(path, line.split(), f"line {lineno} {line.strip()!r}", elements) or fmt
    if fmt not in _PLY_FORMATS:
        raise _fail(
            path, f"PLY format '{fmt}' is not supported (accepted: {', '.join(_PLY_FORMATS)})"
        )
    return fmt, elements, body, len(lines) + 2


def _header_line(path: Path, tok: list[str], where: str, elements: list[_PlyElement]) -> str:
    """Read one header line (its fields ``tok``): an element or a property is added to
    ``elements``; the format is returned ("" for any other line)."""
    if not tok or tok[0] in ("ply", "comment", "obj_info"):
        return ""
    if tok[0] == "format" and len(tok) >= 2:
        return tok[1]
    if tok[0] == "element" and len(tok) == 3:
        elements.append(_element(path, tok, where))
    elif tok[0] == "property":
        _add_property(path, tok, where, elements)
    else:
        raise _fail(path, f"{where} is not a PLY header line (format, element, property)")
    return ""


def _element(path: Path, tok: list[str], where: str) -> _PlyElement:
    """An ``element NAME COUNT`` header line."""
    if not tok[2].isdigit():
        raise _fail(path, f"{where}: the count '{tok[2]}' is not an integer >= 0")
    return _PlyElement(tok[1], int(tok[2]))


def _add_property(path: Path, tok: list[str], where: str, elements: list[_PlyElement]) -> None:
    """A ``property TYPE NAME`` or ``property list COUNT_TYPE ITEM_TYPE NAME`` header line,
    added to the last element."""
    if not elements:
        raise _fail(path, f"{where}: a property before any element")
    if len(tok) == 5 and tok[1] == "list":
        count_dt, item_dt = _ply_type(path, tok[2], where), _ply_type(path, tok[3], where)
        if count_dt[0] not in "iu" or (elements[-1].name == "face" and item_dt[0] not in "iu"):
            raise _fail(path, f"{where}: list counts and vertex indices must be integer types")
        elements[-1].props.append(_PlyProperty(tok[4], item_dt, count_dt))
    elif len(tok) == 3:
        elements[-1].props.append(_PlyProperty(tok[2], _ply_type(path, tok[1], where)))
    else:
        raise _fail(path, f"{where} is not a PLY header line (format, element, property)")


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
    return _binary_list_rows(el, body, off, order, truncated)


def _binary_list_rows(
    el: _PlyElement, body: bytes, off: int, order: str, truncated: Exception
) -> tuple[dict[str, Any], int]:
    """:func:`_binary_rows` of an element with list properties: row by row."""
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
    if fmt == "ascii":
        columns = _ascii_columns(path, elements, body, first_line)
    else:
        columns = _binary_columns(
            path, elements, body, "<" if fmt == "binary_little_endian" else ">"
        )
    return _ply_mesh(path, elements, columns)


def _ascii_columns(
    path: Path, elements: list[_PlyElement], body: bytes, first_line: int
) -> dict[str, dict[str, Any]]:
    """Each element's columns of an ASCII body (its lines counted from ``first_line``)."""
    columns: dict[str, dict[str, Any]] = {}
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
    return columns


def _binary_columns(
    path: Path, elements: list[_PlyElement], body: bytes, order: str
) -> dict[str, dict[str, Any]]:
    """Each element's columns of a binary body of byte order ``order`` (``<`` or ``>``)."""
    columns: dict[str, dict[str, Any]] = {}
    off = 0
    for el in elements:
        columns[el.name], off = _binary_rows(path, el, body, off, order)
    if body[off:].strip():
        raise _fail(
            path,
            f"{len(body) - off} bytes after the last element: the header's element counts "
            "do not match the data",
        )
    return columns


def _ply_mesh(path: Path, elements: list[_PlyElement], columns: dict[str, dict[str, Any]]) -> Mesh:
    """The (vertices, triangles) of parsed PLY elements, with the indices checked."""
    names = [el.name for el in elements]
    if "vertex" not in names or "face" not in names:
        raise _fail(path, "a PLY mesh needs a 'vertex' and a 'face' element")
    verts = _vertices(path, elements[names.index("vertex")], columns["vertex"])
    face = elements[names.index("face")]
    lists = [p.name for p in face.props if p.count_dtype is not None]
    if not lists:
        raise _fail(path, "the face element has no list property (vertex_indices)")
    key = next((n for n in ("vertex_indices", "vertex_index") if n in lists), lists[0])
    return verts, _triangles(path, columns["face"][key], len(verts))


def _vertices(path: Path, vertex: _PlyElement, columns: dict[str, Any]) -> np.ndarray:
    """The vertices (V, 3) of the vertex element's x, y, z columns."""
    scalar = {p.name for p in vertex.props if p.count_dtype is None}
    for axis in "xyz":
        if axis not in scalar:
            raise _fail(path, f"the vertex element has no '{axis}' property (it needs x, y, z)")
    return np.stack([np.asarray(columns[c], dtype=float) for c in "xyz"], axis=1)


def _triangles(path: Path, polygons: list[Any], n_verts: int) -> np.ndarray:
    """Triangle fans (T, 3) of the faces' vertex lists, each checked."""
    triangles: list[list[int]] = []
    for k, poly in enumerate(polygons):
        idx = [int(i) for i in poly]
        if len(idx) < 3:
            raise _fail(path, f"face {k} has {len(idx)} vertices; a face needs at least 3")
        bad = [i for i in idx if not 0 <= i < n_verts]
        if bad:
            raise _fail(
                path,
                f"face {k} refers to vertex {bad[0]}, but the file has {n_verts} vertices "
                "(numbered from 0)",
            )
        triangles.extend(fan(idx))
    if not triangles:
        raise _fail(path, "PLY file has no faces")
    return np.asarray(triangles, dtype=np.int64)
