"""Target geometry: named parts (triangle meshes or analytic spheres) carrying materials."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError, did_you_mean
from speclight.target.materials import Material


@dataclass(frozen=True, eq=False)
class Part:
    """One named part of a target.

    Parameters
    ----------
    name
        Part name (unique within a target).
    vertices_m
        (V, 3) vertex positions in the body frame [m].
    faces
        (F, 3) vertex indices of the triangles (counter-clockwise seen from outside).
    material
        Its material.
    sphere_radius_m
        If set, the part is an exact sphere of this radius [m] centred at
        ``sphere_center_m``; the mesh is then only a tessellated stand-in.
    sphere_center_m
        Centre of the analytic sphere [m].
    """

    name: str
    vertices_m: NDArray[np.float64]
    faces: NDArray[np.int64]
    material: Material
    sphere_radius_m: float | None = None
    sphere_center_m: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        v = np.ascontiguousarray(self.vertices_m, dtype=float)
        f = np.ascontiguousarray(self.faces, dtype=np.int64)
        where = f"target.parts.{self.name}"
        problem = _mesh_problem(v, f)
        if problem is not None:
            raise InputError(problem, field=where)
        if self.sphere_radius_m is not None and not self.sphere_radius_m > 0:
            raise InputError(f"radius_m = {self.sphere_radius_m} must be > 0", field=where)
        object.__setattr__(self, "vertices_m", v)
        object.__setattr__(self, "faces", f)

    @property
    def area_m2(self) -> float:
        """Surface area [m²] (exact for analytic spheres)."""
        if self.sphere_radius_m is not None:
            return float(4.0 * np.pi * self.sphere_radius_m**2)
        t = self.vertices_m[self.faces]
        return float(
            0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1).sum()
        )


def _mesh_problem(v: NDArray[np.float64], f: NDArray[np.int64]) -> str | None:
    """What is wrong with a part's vertices (V, 3) and faces (F, 3), or None."""
    if v.ndim != 2 or v.shape[1] != 3 or not np.all(np.isfinite(v)):
        return f"vertices_m must be a finite (V, 3) array, got {v.shape}"
    if f.ndim != 2 or f.shape[1] != 3 or f.size == 0:
        return f"faces must be a non-empty (F, 3) array, got {f.shape}"
    if f.min() < 0 or f.max() >= len(v):
        return f"face indices must lie in 0..{len(v) - 1}, got {f.min()}..{f.max()}"
    return None


@dataclass(frozen=True, eq=False)
class Target:
    """A target: its parts, each with a material, in the body frame."""

    parts: tuple[Part, ...] = field(default_factory=tuple)

    def __post_init__(self) -> None:
        parts = tuple(self.parts)
        if not parts:
            raise InputError("a target needs at least one part", field="target")
        names = [p.name for p in parts]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise InputError(
                f"part names must be unique; repeated: {', '.join(dup)}", field="target"
            )
        object.__setattr__(self, "parts", parts)

    @property
    def part_names(self) -> tuple[str, ...]:
        """Names of the parts, in order."""
        return tuple(p.name for p in self.parts)

    @property
    def materials(self) -> tuple[Material, ...]:
        """Distinct materials (equal values count once), in order of first use."""
        seen: list[Material] = []
        for p in self.parts:
            if p.material not in seen:
                seen.append(p.material)
        return tuple(seen)

    @property
    def part_material_index(self) -> NDArray[np.int64]:
        """Index into :attr:`materials` of each part's material."""
        mats = list(self.materials)
        return np.array([mats.index(p.material) for p in self.parts], dtype=np.int64)

    def bounding_sphere(self) -> tuple[NDArray[np.float64], float]:
        """Centre [m] and radius [m] of a sphere enclosing every part."""
        pts = []
        for p in self.parts:
            if p.sphere_radius_m is not None:
                c = np.asarray(p.sphere_center_m, dtype=float)
                r = p.sphere_radius_m
                pts.append(c + r * np.vstack([np.eye(3), -np.eye(3)]))
            else:
                pts.append(p.vertices_m)
        allp = np.vstack(pts)
        centre = 0.5 * (allp.min(axis=0) + allp.max(axis=0))
        radius = 0.0
        for p in self.parts:
            if p.sphere_radius_m is not None:
                d = np.linalg.norm(np.asarray(p.sphere_center_m) - centre) + p.sphere_radius_m
            else:
                d = np.linalg.norm(p.vertices_m - centre, axis=1).max()
            radius = max(radius, float(d))
        return centre, radius


def assign_materials(
    part_names: Sequence[str],
    materials: Material | Mapping[str, Material],
    *,
    source: str | None = None,
) -> dict[str, Material]:
    """Map every part to a material; a name that is not a part is an :class:`InputError`.

    ``materials`` is one material for all parts, or a mapping part name -> material whose
    key ``"*"`` (optional) covers the parts not named.
    """
    if isinstance(materials, Material):
        return dict.fromkeys(part_names, materials)
    found = ", ".join(part_names)
    for key in materials:
        if key != "*" and key not in part_names:
            raise InputError(
                f"material given for part '{key}', which is not in the shape"
                f"{did_you_mean(key, part_names)} (parts found: {found})",
                source=source,
                field=f"target.materials.{key}",
            )
    out: dict[str, Material] = {}
    missing = []
    for name in part_names:
        m = materials.get(name, materials.get("*"))
        if m is None:
            missing.append(name)
        else:
            out[name] = m
    if missing:
        raise InputError(
            f"no material for part(s) {', '.join(missing)}; give each part a material or a "
            f"default under '*' (parts found: {found})",
            source=source,
            field="target.materials",
        )
    return out
