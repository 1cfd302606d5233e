"""The Mitsuba scene of path mode: parts, BSDFs, the Sun and the sensors (see :mod:`.path`).

BSDFs are two-sided, like the single-scattering mode; each model gives its own
(:meth:`speclight.render.bsdfs.MaterialBsdf.path_bsdf`): ``diffuse``; ``roughconductor``
with the Beckmann or GGX distribution, Fresnel from n,k, or a reflectance with
``material='none'`` (F = 1 scaled by the reflectance); smooth ``conductor``; ``plastic``
materials as the coated diffuse BSDF of :mod:`.bsdfs.path_coat` (coat index varying with
wavelength: the whole spectrum in one render), or, with ``coat='grouped'``, as Mitsuba's
``plastic`` / ``roughplastic`` with one index per group of bins (:mod:`.bsdfs.path_plastic`,
the previous model, kept as a reference); RGL measured materials through Mitsuba's
``measured`` plugin. The Sun is a ``directional`` emitter of unit spectral irradiance or,
with ``solar_disk``, a far sphere emitter subtending the solar disk. The sensor is
orthographic along the line of sight, its ``specfilm`` holding one box response per
wavelength bin (the grouped reference and benchmarks render through it; path mode itself
samples its own rays, :mod:`.path_sampling`).

Reference: Jakob et al., Mitsuba 3 renderer, https://mitsuba-renderer.org (2022).
"""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.render.bsdfs import material_bsdf
from speclight.render.camera import image_axes
from speclight.render.shading import sun_disk_sin2
from speclight.target.materials import Material
from speclight.target.parts import Target

F64 = NDArray[np.float64]
#: Longest path (number of bounces + 1) followed; Russian roulette starts after 5.
MAX_DEPTH = 16
#: Distance of the solar-disk sphere from the target's centre, in bounding radii: the
#: direction to the Sun varies across the target by < 1 / SUN_DISTANCE_FACTOR rad (1e-5 rad
#: against a disk radius of 4.65e-3 rad).
SUN_DISTANCE_FACTOR = 1.0e5


def _bsdf(m: Material, lo: float, hi: float, coat: str = "spectral") -> Any:
    """Mitsuba BSDF dict of a material (two-sided, like the single-scattering mode)."""
    return {"type": "twosided", "material": material_bsdf(m, "path").path_bsdf(lo, hi, coat)}


def _sun(lo: float, hi: float, solar_disk: bool) -> dict[str, Any]:
    """Sun of unit spectral irradiance [W m-2 nm-1] over [lo, hi] nm: a ``directional`` (delta)
    emitter, or with ``solar_disk`` a far uniform sphere subtending the solar disk.

    A sphere of radius r seen from distance D subtends a cone of half-angle theta_s with
    sin(theta_s) = r / D; a uniform radiance L gives the irradiance E = pi L sin^2(theta_s)
    on a surface facing it (Lambert's law over the cone). Mitsuba samples the sphere
    emitter by its subtended cone, so the noise stays that of the point Sun for rough
    surfaces, while mirrors reflect it (the sphere is placed per epoch by
    :func:`_epoch_transforms`).
    """
    unit = {"type": "regular", "wavelength_min": lo, "wavelength_max": hi}
    if not solar_disk:
        return {
            "type": "directional",
            "direction": [0.0, 0.0, -1.0],
            "irradiance": {**unit, "values": "1, 1"},
        }
    radiance = 1.0 / (np.pi * sun_disk_sin2())
    return {
        "type": "sphere",
        "to_world": _sun_sphere_transform(np.zeros(3), 1.0, np.array([0.0, 0.0, 1.0])),
        "emitter": {
            "type": "area",
            "radiance": {**unit, "values": f"{radiance:.9g}, {radiance:.9g}"},
        },
    }


def _sun_sphere_transform(centre: F64, radius: float, sun: F64) -> Any:
    """Place the solar sphere at :data:`SUN_DISTANCE_FACTOR` bounding radii along ``sun``."""
    import mitsuba as mi

    dist = SUN_DISTANCE_FACTOR * radius
    pos = centre + dist * np.asarray(sun, float)
    r = dist * np.sqrt(sun_disk_sin2())
    return mi.ScalarTransform4f().translate(pos.tolist()) @ mi.ScalarTransform4f().scale([r, r, r])


def _film(edges_lo: F64, edges_hi: F64, width: int, height: int, bins: range) -> dict[str, Any]:
    bands = {
        f"band{k:04d}": {
            "type": "regular",
            "wavelength_min": float(edges_lo[k]),
            "wavelength_max": float(edges_hi[k]),
            "values": "1, 1",
        }
        for k in bins
    }
    return {
        "type": "specfilm",
        "width": width,
        "height": height,
        "rfilter": {"type": "box"},
        **bands,
    }


def build_scene(
    target: Target,
    edges_lo: F64,
    edges_hi: F64,
    resolution_px: int,
    spp: int,
    solar_disk: bool = False,
    groups: list[tuple[int, int]] | None = None,
    coat: str = "spectral",
) -> tuple[Any, Any]:
    """Mitsuba scene and its parameters (:func:`set_epoch` updates them per epoch).

    One orthographic sensor ``sensor{j}`` per group of bins (``groups``: (first, end) bin
    indices; all bins in one group by default; none for ``[]``: path mode samples its own
    rays, :mod:`.path_sampling`).
    ``coat``: ``'spectral'`` or ``'grouped'`` plastic materials (module docstring).
    """
    import mitsuba as mi

    lo, hi = float(edges_lo[0]), float(edges_hi[-1])
    scene: dict[str, Any] = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": MAX_DEPTH, "hide_emitters": True},
        "sun": _sun(lo, hi, solar_disk),
    }
    sampler = {"type": "independent", "sample_count": spp}
    for j, (a, b) in enumerate([(0, len(edges_lo))] if groups is None else groups):
        scene[f"sensor{j}"] = {
            "type": "orthographic",
            "to_world": mi.ScalarTransform4f(),
            "film": _film(edges_lo, edges_hi, resolution_px, resolution_px, range(a, b)),
            "sampler": sampler,
        }
    with tempfile.TemporaryDirectory(prefix="speclight-") as tmp:
        for k, p in enumerate(target.parts):
            bsdf = _bsdf(p.material, lo, hi, coat)
            if p.sphere_radius_m is not None:
                scene[f"part{k}"] = {
                    "type": "sphere",
                    "center": list(p.sphere_center_m),
                    "radius": p.sphere_radius_m,
                    "bsdf": bsdf,
                }
                continue
            mesh = mi.Mesh(
                p.name,
                vertex_count=len(p.vertices_m),
                face_count=len(p.faces),
                has_vertex_normals=False,
                has_vertex_texcoords=False,
            )
            params = mi.traverse(mesh)
            # the buffers' own types: mi.Float / mi.UInt32 in JIT variants, but dynamic arrays
            # (drjit.scalar.ArrayXf / ArrayXu) in the scalar ones, where mi.Float is one number
            positions, faces = type(params["vertex_positions"]), type(params["faces"])
            params["vertex_positions"] = positions(p.vertices_m.astype(np.float32).ravel())
            params["faces"] = faces(p.faces.astype(np.uint32).ravel())
            params.update()
            path = Path(tmp) / f"part{k}.ply"
            mesh.write_ply(str(path))
            scene[f"part{k}"] = {
                "type": "ply",
                "filename": str(path),
                "face_normals": True,
                "bsdf": bsdf,
            }
        loaded = mi.load_dict(scene, optimize=False)
    return loaded, mi.traverse(loaded)


def set_epoch(
    mi: Any,
    params: Any,
    target: Target,
    sun: F64,
    obs: F64,
    solar_disk: bool,
    sensor: str | None = None,
) -> None:
    """Point the Sun and the sensor ``sensor`` (if given) for one epoch; update the scene."""
    sensor_tf, light_tf = _epoch_transforms(mi, target, sun, obs, solar_disk)
    if sensor is not None:
        for key in _sensor_keys(params, sensor):
            params[key] = sensor_tf
    params["sun.to_world"] = light_tf
    params.update()


def _sensor_keys(params: Any, sensor: str) -> list[str]:
    keys = [k for k in params.keys() if k.startswith(sensor + ".") and k.endswith("to_world")]
    if not keys:
        raise KeyError(f"no to_world parameter under '{sensor}'")
    return keys


def _epoch_transforms(
    mi: Any, target: Target, sun: F64, obs: F64, solar_disk: bool = False
) -> tuple[Any, Any]:
    centre, radius = target.bounding_sphere()
    if solar_disk:
        light = _sun_sphere_transform(centre, radius, sun)
        sensor, _ = _epoch_transforms(mi, target, sun, obs)
        return sensor, light
    _, up = image_axes(obs[None, :])
    eye = centre + 2.0 * radius * obs
    sensor = mi.ScalarTransform4f().look_at(
        origin=eye.tolist(), target=centre.tolist(), up=up[0].tolist()
    ) @ mi.ScalarTransform4f().scale([radius, radius, 1.0])
    light = mi.ScalarTransform4f().look_at(
        origin=[0.0, 0.0, 0.0], target=(-sun).tolist(), up=_any_perpendicular(sun).tolist()
    )
    return sensor, light


def _any_perpendicular(v: F64) -> F64:
    a = np.array([1.0, 0.0, 0.0]) if abs(v[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    p = np.cross(v, a)
    return p / np.linalg.norm(p)
