"""Read STL and glTF (``.gltf``/``.glb``) target meshes through ``trimesh``.

Parts: an STL file is one part (named for the file stem; STL has no groups or materials). In a
glTF file every mesh primitive placed in the scene becomes a part named for its material when
the material has a name, else for its mesh (the name ``target.materials`` keys refer to);
primitives of the same name are joined into one part. Node transforms are applied.
Coordinates are file units (glTF: metres); ``scale_m_per_unit`` scales them later.

References: ISO/IEC 12113:2022 (glTF 2.0); 3D Systems, "StereoLithography Interface
Specification" (1989); trimesh (https://trimesh.org) reads both.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from speclight.target.mesh_common import Mesh
from speclight.target.mesh_common import mesh_error as _fail

#: File suffixes read here.
TRIMESH_SUFFIXES = (".stl", ".gltf", ".glb")


def _part_name(geometry: Any, geometry_name: str) -> str:
    material = getattr(getattr(geometry, "visual", None), "material", None)
    name = getattr(material, "name", None)
    return str(name) if name else str(geometry_name)


def read_trimesh(path: Path) -> dict[str, Mesh]:
    """Parts of an STL or glTF file: name -> (vertices (V, 3), faces (F, 3)).

    Raises
    ------
    InputError
        The file cannot be read as a triangle mesh, or holds no faces.
    """
    import trimesh

    try:
        scene: Any = trimesh.load(str(path), force="scene", process=False)
    except Exception as exc:  # trimesh raises many types for a malformed file
        raise _fail(path, f"cannot be read as a mesh by trimesh: {exc}") from None
    pieces: dict[str, list[Mesh]] = {}
    for node in scene.graph.nodes_geometry:
        transform, geometry_name = scene.graph[node]
        geometry = scene.geometry.get(geometry_name)
        faces = getattr(geometry, "faces", None)
        if faces is None or len(faces) == 0:
            continue  # points, paths: not a surface
        v = np.asarray(geometry.vertices, dtype=np.float64)
        v = v @ np.asarray(transform, dtype=np.float64)[:3, :3].T + transform[:3, 3]
        name = path.stem if path.suffix.lower() == ".stl" else _part_name(geometry, geometry_name)
        pieces.setdefault(name, []).append((v, np.asarray(faces, dtype=np.int64)))
    if not pieces:
        raise _fail(path, "no triangle faces found")
    return {name: _joined(parts) for name, parts in pieces.items()}


def _joined(parts: list[Mesh]) -> Mesh:
    """One mesh of several (vertices renumbered), keeping only the vertices faces use."""
    offsets = np.cumsum([0] + [len(v) for v, _ in parts[:-1]])
    v = np.concatenate([v for v, _ in parts])
    f = np.concatenate([f + o for (_, f), o in zip(parts, offsets, strict=True)])
    used, inverse = np.unique(f, return_inverse=True)
    return v[used], inverse.reshape(-1, 3)
