"""Read target meshes: Wavefront OBJ (groups/objects become parts) and PLY (one part per file).

OBJ: Wavefront Technologies, "Object Files (.obj)", Advanced Visualizer manual, appendix B.
PLY: Turk 1994, "The PLY polygon file format" (Stanford). Coordinates are taken as metres
times ``scale_m_per_unit``; polygons are split into triangle fans.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.target.materials import Material
from speclight.target.parts import Part, Target, assign_materials

Mesh = tuple[NDArray[np.float64], NDArray[np.int64]]
_PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
    "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}  # fmt: skip


def _fan(poly: list[int]) -> list[list[int]]:
    return [[poly[0], poly[k], poly[k + 1]] for k in range(1, len(poly) - 1)]


def read_obj(path: Path) -> dict[str, Mesh]:
    """Parts of an OBJ file: name -> (vertices (V, 3), faces (F, 3)), compacted per part."""
    verts: list[list[float]] = []
    faces: dict[str, list[list[int]]] = {}
    current = path.stem
    for lineno, raw in enumerate(path.read_text(errors="replace").splitlines(), 1):
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
            raise InputError(f"line {lineno} {raw.strip()!r}: {exc}", source=str(path)) from None
    if not faces:
        raise InputError("no faces found (need 'f' lines)", source=str(path))
    v = np.asarray(verts, dtype=float)
    out = {}
    for name, f in faces.items():
        fa = np.asarray(f, dtype=np.int64)
        if fa.min() < 0 or fa.max() >= len(v):
            raise InputError(
                f"part '{name}' refers to a vertex that does not exist", source=str(path)
            )
        used, inverse = np.unique(fa, return_inverse=True)
        out[name] = (v[used], inverse.reshape(-1, 3))
    return out


def read_ply(path: Path) -> Mesh:
    """Vertices and triangulated faces of an ASCII or binary PLY file."""
    data = path.read_bytes()
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise InputError("not a PLY file (no 'ply' magic or 'end_header')", source=str(path))
    header = data[:end].decode("ascii", errors="replace").splitlines()
    body = data[data.index(b"\n", end) + 1 :]
    fmt = ""
    elements: list[tuple[str, int, list[tuple[str, ...]]]] = []
    for line in header:
        tok = line.split()
        if not tok:
            continue
        if tok[0] == "format":
            fmt = tok[1]
        elif tok[0] == "element":
            elements.append((tok[1], int(tok[2]), []))
        elif tok[0] == "property" and elements:
            elements[-1][2].append(tuple(tok[1:]))
    if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise InputError(f"unsupported PLY format '{fmt}'", source=str(path))
    verts = np.zeros((0, 3))
    faces: list[list[int]] = []
    if fmt == "ascii":
        lines = body.decode("ascii", errors="replace").split("\n")
        pos = 0
        for name, count, props in elements:
            rows = lines[pos : pos + count]
            pos += count
            if name == "vertex":
                names = [p[-1] for p in props]
                arr = np.array([r.split()[: len(names)] for r in rows], dtype=float)
                verts = arr[:, [names.index(c) for c in "xyz"]]
            elif name == "face":
                for r in rows:
                    vals = [int(x) for x in r.split()]
                    faces.extend(_fan(vals[1 : 1 + vals[0]]))
    else:
        order = "<" if fmt == "binary_little_endian" else ">"
        off = 0
        for name, count, props in elements:
            if name == "vertex":
                dt = np.dtype([(p[-1], order + _PLY_TYPES[p[0]]) for p in props])
                arr = np.frombuffer(body, dtype=dt, count=count, offset=off)
                off += dt.itemsize * count
                verts = np.stack([arr[c].astype(float) for c in "xyz"], axis=1)
            elif name == "face" and len(props) == 1 and props[0][0] == "list":
                ct = np.dtype(order + _PLY_TYPES[props[0][1]])
                it = np.dtype(order + _PLY_TYPES[props[0][2]])
                for _ in range(count):
                    n = int(np.frombuffer(body, ct, 1, off)[0])
                    off += ct.itemsize
                    faces.extend(_fan(np.frombuffer(body, it, n, off).astype(int).tolist()))
                    off += it.itemsize * n
            else:
                raise InputError(
                    f"binary PLY element '{name}' is not supported (vertex, face only)",
                    source=str(path),
                )
    if len(verts) == 0 or not faces:
        raise InputError("PLY file has no vertices or no faces", source=str(path))
    return verts, np.asarray(faces, dtype=np.int64)


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
    """
    paths = [Path(path)] if isinstance(path, str | Path) else [Path(p) for p in path]
    meshes: dict[str, Mesh] = {}
    for p in paths:
        if not p.is_file():
            raise InputError("mesh file not found", source=str(p), field="target.shape.mesh_file")
        ext = p.suffix.lower()
        if ext == ".obj":
            meshes.update(read_obj(p))
        elif ext == ".ply":
            meshes[p.stem] = read_ply(p)
        else:
            raise InputError(
                f"unsupported mesh format '{ext}' (accepted: .obj, .ply)",
                source=str(p),
                field="target.shape.mesh_file",
            )
    source = ", ".join(str(p) for p in paths)
    mats = assign_materials(list(meshes), part_materials, source=source)
    return Target(tuple(Part(n, v * scale_m_per_unit, f, mats[n]) for n, (v, f) in meshes.items()))
