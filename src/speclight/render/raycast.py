"""Ray casting against a target: Mitsuba/Dr.Jit (vectorised) or plain numpy (fallback).

Both casters answer the same two questions for arrays of rays: the first hit (distance,
geometric normal, part index) and whether a ray is blocked (shadow test). The numpy caster is
an independent implementation (Möller & Trumbore 1997, doi:10.1080/10867651.1997.10487468,
for triangles; the quadratic for spheres) used without Mitsuba, with scalar variants, and to
cross-check the Mitsuba one. It may run in several processes over blocks of epochs
(:func:`numpy_processes` says how many a process may start).

A Mitsuba caster's scene belongs to the variant it was built in, while Mitsuba's variant is
process-wide: a caster kept for later (a reflectivity map's engine, cached per process) may
meet another variant set by a render in between (a path-mode map), so each of its calls sets
its own variant again.
"""

from __future__ import annotations

import multiprocessing
import os
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from speclight.render.variant import activate, render_threads
from speclight.target.parts import Target

F64 = NDArray[np.float64]


@dataclass
class Hits:
    """First hits of M rays: ``hit`` (M,), ``t_m`` (M,) [m], ``normal`` (M, 3), ``part`` (M,)."""

    hit: NDArray[np.bool_]
    t_m: F64
    normal: F64
    part: NDArray[np.int64]


class Caster(Protocol):
    """What the renderers need from a ray caster."""

    name: str

    def intersect(self, origin: F64, direction: F64) -> Hits: ...

    def occluded(self, origin: F64, direction: F64, normal: F64) -> NDArray[np.bool_]: ...


def _no_hits() -> Hits:
    """The hits of zero rays."""
    return Hits(np.zeros(0, bool), np.zeros(0), np.zeros((0, 3)), np.zeros(0, np.int64))


def _offset(target: Target) -> float:
    """Shadow-ray start offset along the normal [m]: 1e-5 of the target size."""
    return 1e-5 * target.bounding_sphere()[1]


class NumpyCaster:
    """Brute-force ray casting in numpy (every ray against every triangle, in chunks)."""

    name = "numpy"

    def __init__(self, target: Target) -> None:
        tris, part_of_tri = [], []
        self.spheres: list[tuple[F64, float, int]] = []
        for k, p in enumerate(target.parts):
            if p.sphere_radius_m is not None:
                self.spheres.append((np.asarray(p.sphere_center_m, float), p.sphere_radius_m, k))
            else:
                tris.append(p.vertices_m[p.faces])
                part_of_tri.append(np.full(len(p.faces), k))
        self.tri = np.concatenate(tris) if tris else np.zeros((0, 3, 3))
        self.tri_part = np.concatenate(part_of_tri) if part_of_tri else np.zeros(0, np.int64)
        e1 = self.tri[:, 1] - self.tri[:, 0]
        e2 = self.tri[:, 2] - self.tri[:, 0]
        n = np.cross(e1, e2)
        self.tri_n = n / np.linalg.norm(n, axis=1, keepdims=True)
        self.e1, self.e2 = e1, e2
        self.eps = _offset(target)

    def _triangles(self, o: F64, d: F64, tmin: float) -> tuple[F64, NDArray[np.int64]]:
        m, t_count = len(o), len(self.tri)
        best_t = np.full(m, np.inf)
        best = np.full(m, -1, dtype=np.int64)
        if t_count == 0:
            return best_t, best
        chunk = 2048
        for a in range(0, m, chunk):
            oc, dc = o[a : a + chunk], d[a : a + chunk]
            sel = self._cull(oc, dc)
            if sel.size == 0:
                continue
            t, j = self._test(oc, dc, sel, tmin)
            best_t[a : a + chunk] = t
            best[a : a + chunk] = j
        return best_t, best

    def _cull(self, o: F64, d: F64) -> NDArray[np.int64]:
        """Triangles that parallel rays (same direction) may hit: 2-D box overlap test."""
        if np.ptp(d, axis=0).max() > 1e-9:
            return np.arange(len(self.tri))
        w = d[0]
        a = np.array([1.0, 0.0, 0.0]) if abs(w[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        u = np.cross(w, a)
        u /= np.linalg.norm(u)
        v = np.cross(w, u)
        pu, pv = o @ u, o @ v
        tu, tv = self.tri @ u, self.tri @ v
        pad = 1e-9 * (1.0 + np.abs(tu).max() + np.abs(tv).max())
        keep = (
            (tu.min(axis=1) <= pu.max() + pad)
            & (tu.max(axis=1) >= pu.min() - pad)
            & (tv.min(axis=1) <= pv.max() + pad)
            & (tv.max(axis=1) >= pv.min() - pad)
        )
        return np.flatnonzero(keep)

    def _test(
        self, o: F64, d: F64, sel: NDArray[np.int64], tmin: float
    ) -> tuple[F64, NDArray[np.int64]]:
        """Möller-Trumbore of rays (M,) against triangles ``sel``: nearest t and index."""
        v0 = [self.tri[None, sel, 0, c] for c in range(3)]
        e1 = [self.e1[None, sel, c] for c in range(3)]
        e2 = [self.e2[None, sel, c] for c in range(3)]
        ox, oy, oz = (o[:, c, None] for c in range(3))
        dx, dy, dz = (d[:, c, None] for c in range(3))
        px, py, pz = dy * e2[2] - dz * e2[1], dz * e2[0] - dx * e2[2], dx * e2[1] - dy * e2[0]
        det = px * e1[0] + py * e1[1] + pz * e1[2]
        ok = np.abs(det) > 1e-14
        inv = 1.0 / np.where(ok, det, 1.0)
        sx, sy, sz = ox - v0[0], oy - v0[1], oz - v0[2]
        u = (sx * px + sy * py + sz * pz) * inv
        qx, qy, qz = sy * e1[2] - sz * e1[1], sz * e1[0] - sx * e1[2], sx * e1[1] - sy * e1[0]
        v = (qx * dx + qy * dy + qz * dz) * inv
        t = (qx * e2[0] + qy * e2[1] + qz * e2[2]) * inv
        good = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > tmin)
        t = np.where(good, t, np.inf)
        j = np.argmin(t, axis=1)
        tj = np.take_along_axis(t, j[:, None], axis=1)[:, 0]
        return tj, np.where(np.isfinite(tj), sel[j], -1)

    def _spheres(self, o: F64, d: F64, tmin: float) -> tuple[F64, NDArray[np.int64], F64]:
        best_t = np.full(len(o), np.inf)
        which = np.full(len(o), -1, dtype=np.int64)
        normal = np.zeros_like(o)
        for c, r, k in self.spheres:
            oc = o - c
            b = np.einsum("mk,mk->m", oc, d)
            disc = b * b - (np.einsum("mk,mk->m", oc, oc) - r * r)
            sq = np.sqrt(np.maximum(disc, 0.0))
            t1, t2 = -b - sq, -b + sq
            t = np.where(t1 > tmin, t1, np.where(t2 > tmin, t2, np.inf))
            t = np.where(disc >= 0, t, np.inf)
            closer = t < best_t
            best_t = np.where(closer, t, best_t)
            which = np.where(closer, k, which)
            pos = o + np.where(np.isfinite(t), t, 0.0)[:, None] * d
            normal = np.where(closer[:, None], (pos - c) / r, normal)
        return best_t, which, normal

    def intersect(self, origin: F64, direction: F64) -> Hits:
        t_tri, j = self._triangles(origin, direction, 0.0)
        t_sph, k_sph, n_sph = self._spheres(origin, direction, 0.0)
        use_sph = t_sph < t_tri
        t = np.minimum(t_tri, t_sph)
        hit = np.isfinite(t)
        jj = np.maximum(j, 0)
        normal = np.where(use_sph[:, None], n_sph, self.tri_n[jj] if len(self.tri) else n_sph)
        part = np.where(use_sph, k_sph, self.tri_part[jj] if len(self.tri) else -1)
        return Hits(hit, np.where(hit, t, np.nan), normal, np.where(hit, part, -1))

    def occluded(self, origin: F64, direction: F64, normal: F64) -> NDArray[np.bool_]:
        o = origin + self.eps * normal
        t_tri, _ = self._triangles(o, direction, self.eps)
        t_sph, _, _ = self._spheres(o, direction, self.eps)
        return np.isfinite(np.minimum(t_tri, t_sph))


def numpy_processes(requested: int | None) -> int:
    """Processes the numpy ray caster may run in, at most ``requested`` (``None``: the cores).

    One inside a daemonic process (a Dask worker, a pool's worker: such a process cannot
    start others); at most ``SPECLIGHT_RENDER_THREADS`` where it gives this process's share of
    the cores (each worker of a local Dask cluster); at least one.
    """
    if multiprocessing.current_process().daemon:
        return 1
    n = int(requested) if requested is not None else os.cpu_count() or 1
    share = render_threads()
    return max(1, min(n, share) if share is not None else n)


class MitsubaCaster:
    """Ray casting with Mitsuba's vectorised ``ray_intersect`` / ``ray_test`` (llvm or cuda)."""

    def __init__(self, target: Target, variant: str) -> None:
        mi = activate(variant)
        import drjit as dr

        self.name = variant
        self.mi, self.dr = mi, dr
        shapes: dict[str, object] = {}
        self.shape_part: list[tuple[object, int]] = []
        tri_v, tri_f, face_part, off = [], [], [], 0
        for k, p in enumerate(target.parts):
            if p.sphere_radius_m is not None:
                s = mi.load_dict(
                    {
                        "type": "sphere",
                        "center": list(p.sphere_center_m),
                        "radius": p.sphere_radius_m,
                    }
                )
                shapes[f"sphere_{k}"] = s
                self.shape_part.append((s, k))
            else:
                tri_v.append(p.vertices_m)
                tri_f.append(p.faces + off)
                face_part.append(np.full(len(p.faces), k))
                off += len(p.vertices_m)
        self.face_part = np.concatenate(face_part) if face_part else np.zeros(0, np.int64)
        if tri_v:
            v = np.vstack(tri_v).astype(np.float32)
            f = np.vstack(tri_f).astype(np.uint32)
            mesh = mi.Mesh(
                "target",
                vertex_count=len(v),
                face_count=len(f),
                has_vertex_normals=False,
                has_vertex_texcoords=False,
            )
            params = mi.traverse(mesh)
            params["vertex_positions"] = dr.ravel(mi.Point3f(v.T))
            params["faces"] = dr.ravel(mi.Vector3u(f.T))
            params.update()
            shapes["mesh"] = mesh
            self.mesh = mesh
        else:
            self.mesh = None
        self.scene = mi.load_dict({"type": "scene", **shapes})

    def _rays(self, origin: F64, direction: F64):  # type: ignore[no-untyped-def]
        mi = activate(self.name)  # the scene's variant, whatever ran since (module doc)
        o = np.ascontiguousarray(origin.T, dtype=np.float32)
        d = np.ascontiguousarray(direction.T, dtype=np.float32)
        return mi.Ray3f(mi.Point3f(o), mi.Vector3f(d))

    def intersect(self, origin: F64, direction: F64) -> Hits:
        if len(origin) == 0:  # Dr.Jit aborts the process on empty arrays (jit_var unknown)
            return _no_hits()
        mi, dr = self.mi, self.dr
        si = self.scene.ray_intersect(self._rays(origin, direction))
        valid = si.is_valid()
        part = mi.UInt32(0)
        ids = []
        for shape, k in self.shape_part:
            ids.append((si.shape == mi.ShapePtr(shape), k))
        dr.eval(si.t, si.n, si.prim_index, valid)
        hit = np.array(valid, dtype=bool)
        t = np.array(si.t, dtype=float)
        n = np.array(si.n, dtype=float).T
        prim = np.array(si.prim_index, dtype=np.int64)
        part_np = np.full(len(hit), -1, dtype=np.int64)
        if len(self.face_part):
            part_np = np.where(hit, self.face_part[np.clip(prim, 0, len(self.face_part) - 1)], -1)
        for mask, k in ids:
            part_np = np.where(np.array(mask, dtype=bool) & hit, k, part_np)
        del part
        n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
        return Hits(hit, np.where(hit, t, np.nan), n, part_np)

    def occluded(self, origin: F64, direction: F64, normal: F64) -> NDArray[np.bool_]:
        if len(origin) == 0:  # no lit pixel in the batch: Dr.Jit aborts on empty arrays
            return np.zeros(0, dtype=bool)
        # Offset like Mitsuba's spawn_ray: along the normal, scaled by the coordinate size.
        scale = (1.0 + np.abs(origin).max(axis=1, keepdims=True)) * 2e-5
        o = origin + scale * normal
        ray = self._rays(o, direction)
        return np.array(self.scene.ray_test(ray), dtype=bool)


def make_caster(target: Target, variant: str) -> Caster:
    """The ray caster for a variant: Mitsuba for llvm/cuda variants, numpy otherwise."""
    if variant.startswith(("llvm_", "cuda_")):
        return MitsubaCaster(target, variant)
    return NumpyCaster(target)
