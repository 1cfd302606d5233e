"""Path-traced render: multi-bounce Monte Carlo with Mitsuba 3's spectral ``path`` integrator.

Scene: the target's parts with two-sided BSDFs (``diffuse``; ``roughconductor`` with the
Beckmann or GGX distribution, Fresnel from n,k, or a reflectance with ``material='none'``,
i.e. F = 1 scaled by the reflectance; smooth ``conductor``; ``plastic`` / ``roughplastic``
with one real coat index, the mean n over the grid: the smooth one matches the single mode's
diffuse base, the rough one uses Mitsuba's own rough-coat transmittance, which can differ
from the single mode's smooth-interface (1 - F) factors by several per cent), a
``directional`` Sun of unit spectral irradiance over the whole grid (given as an explicit
spectrum: a bare float would be multiplied by the D65 illuminant), and an ``orthographic``
sensor along the line of sight whose
``specfilm`` has one box response per wavelength bin. Each pixel of channel k holds the
radiance integrated over bin k; dividing by the bin width gives the bin-averaged radiance,
which is scaled by the epoch's solar spectrum (bin averages) afterwards.

The sample budget is split in ``K`` passes with independent seeds; their spread gives the
standard error of the mean per bin. Measured lab BRDF tables are not available in this mode;
RGL ``.bsdf`` measured materials use Mitsuba's ``measured`` plugin (:mod:`.rgl`).
A smooth mirror (``specular``, smooth plastic coat) lit by the directional
(point) Sun reflects no light toward a given observer in this mode (a delta BSDF meets a delta
light); the single-scattering mode models its glint with the finite solar disk.

Reference: Jakob et al., Mitsuba 3 renderer, https://mitsuba-renderer.org (2022);
Veach 1997, Robust Monte Carlo methods for light transport simulation, PhD thesis, Stanford.
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.illumination.solar import bin_edges_nm
from speclight.render.camera import image_axes, primary_rays
from speclight.render.result import RenderImage
from speclight.render.rgl import is_rgl, path_bsdf
from speclight.render.variant import activate
from speclight.target.geometry import Target
from speclight.target.materials import Material
from speclight.target.reflectance import Reflectance

F64 = NDArray[np.float64]
#: Longest path (number of bounces + 1) followed; Russian roulette starts after 5.
MAX_DEPTH = 16
MAX_PASSES = 8


def _spectrum(wl: F64, values: F64) -> dict[str, Any]:
    return {
        "type": "irregular",
        "wavelengths": ", ".join(f"{w:.6g}" for w in wl),
        "values": ", ".join(f"{v:.8g}" for v in values),
    }


def _refl_spectrum(refl: Reflectance, lo: float, hi: float) -> dict[str, Any]:
    if refl.kind == "constant":
        return {"type": "uniform", "value": refl.value}
    grid = np.linspace(lo, hi, max(2, int((hi - lo) / 2.0) + 1))
    return _spectrum(grid, refl.evaluate(grid))


def _bsdf(m: Material, lo: float, hi: float) -> dict[str, Any]:
    """Mitsuba BSDF dict of a material (two-sided, like the single-scattering mode)."""
    refl = m.reflectance
    grid = np.linspace(lo, hi, max(2, int((hi - lo) / 2.0) + 1))
    if m.bsdf == "lambertian":
        inner: dict[str, Any] = {"type": "diffuse", "reflectance": _refl_spectrum(refl, lo, hi)}
    elif m.bsdf in ("beckmann", "ggx", "specular"):
        inner = (
            {"type": "conductor"}
            if m.bsdf == "specular"
            else {
                "type": "roughconductor",
                "distribution": m.bsdf,
                "alpha": float(m.roughness or 0.0),
            }
        )
        if refl.is_fresnel:
            eta = refl.eta(grid)
            inner["eta"] = _spectrum(grid, eta.real)
            inner["k"] = _spectrum(grid, eta.imag)
        else:
            inner["material"] = "none"
            inner["specular_reflectance"] = _refl_spectrum(refl, lo, hi)
    elif m.bsdf == "plastic":
        # Mitsuba's plastic takes one real coat index: the mean n over the grid (the
        # single-scattering mode follows n(lambda)); its linear variant matches that mode.
        assert m.diffuse_reflectance is not None
        inner = {
            "type": "plastic" if m.roughness is None else "roughplastic",
            "int_ior": float(np.mean(refl.eta(grid).real)),
            "ext_ior": 1.0,
            "diffuse_reflectance": _refl_spectrum(m.diffuse_reflectance, lo, hi),
            "nonlinear": False,
        }
        if m.roughness is not None:
            inner.update(distribution="beckmann", alpha=float(m.roughness))
    elif is_rgl(m):
        inner = path_bsdf(m)  # Mitsuba's 'measured' plugin on the RGL .bsdf file
    else:
        raise InputError(
            f"material '{m.name}': bsdf '{m.bsdf}' is not supported in render.mode 'path' yet "
            "(path supports lambertian, beckmann, ggx, specular, plastic and measured RGL "
            ".bsdf files); use render.mode "
            "'single'",
            field="render.mode",
        )
    return {"type": "twosided", "material": inner}


def build_scene(
    target: Target, edges_lo: F64, edges_hi: F64, resolution_px: int, spp: int
) -> tuple[Any, Any]:
    """Mitsuba scene and its parameters (``sensor.to_world``, ``sun.to_world`` are updated)."""
    import mitsuba as mi

    lo, hi = float(edges_lo[0]), float(edges_hi[-1])
    centre, radius = target.bounding_sphere()
    bands = {
        f"band{k:04d}": {
            "type": "regular",
            "wavelength_min": float(a),
            "wavelength_max": float(b),
            "values": "1, 1",
        }
        for k, (a, b) in enumerate(zip(edges_lo, edges_hi, strict=True))
    }
    scene: dict[str, Any] = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": MAX_DEPTH, "hide_emitters": True},
        "sensor": {
            "type": "orthographic",
            "to_world": mi.ScalarTransform4f(),
            "film": {
                "type": "specfilm",
                "width": resolution_px,
                "height": resolution_px,
                "rfilter": {"type": "box"},
                **bands,
            },
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "sun": {
            "type": "directional",
            "direction": [0.0, 0.0, -1.0],
            "irradiance": {
                "type": "regular",
                "wavelength_min": lo,
                "wavelength_max": hi,
                "values": "1, 1",
            },
        },
    }
    with tempfile.TemporaryDirectory(prefix="speclight-") as tmp:
        for k, p in enumerate(target.parts):
            bsdf = _bsdf(p.material, lo, hi)
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
            params["vertex_positions"] = mi.Float(p.vertices_m.astype(np.float32).ravel())
            params["faces"] = mi.UInt32(p.faces.astype(np.uint32).ravel())
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
    del centre, radius
    return loaded, mi.traverse(loaded)


def _epoch_transforms(mi: Any, target: Target, sun: F64, obs: F64) -> tuple[Any, Any]:
    centre, radius = target.bounding_sphere()
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


def render_path(
    target: Target,
    sun_dir: F64,
    obs_dir: F64,
    irradiance: F64,
    wavelength_nm: F64,
    variant: str,
    resolution_px: int,
    samples_per_pixel: int,
    seed: int,
    keep: Iterable[int] = (),
    on_epoch: Callable[[int], None] | None = None,
) -> tuple[F64, F64, dict[int, RenderImage]]:
    """Intensity (N, L), its standard error (N, L) [W sr-1 nm-1] and kept images."""
    if not variant.endswith(("_spectral", "_spectral_polarized")) or variant.endswith("polarized"):
        raise InputError(
            f"render.mode 'path' needs a *_spectral variant, got '{variant}' "
            "(use 'auto', llvm_ad_spectral, cuda_ad_spectral or scalar_spectral)",
            field="render.variant",
        )
    mi = activate(variant)
    # A single wavelength is rendered as a 1 nm wide bin around it.
    lo, hi = bin_edges_nm(wavelength_nm, 1.0 if len(wavelength_nm) == 1 else None)
    width = hi - lo
    passes = max(1, min(MAX_PASSES, samples_per_pixel))
    spp = max(1, samples_per_pixel // passes)
    scene, params = build_scene(target, lo, hi, resolution_px, spp)
    _, radius = target.bounding_sphere()
    pixel_area = (2.0 * radius / resolution_px) ** 2
    n_ep, n_wl = len(sun_dir), len(wavelength_nm)
    mean = np.zeros((n_ep, n_wl))
    err = np.zeros((n_ep, n_wl))
    keep_set = set(keep)
    images: dict[int, RenderImage] = {}
    for e in range(n_ep):
        sensor_tf, light_tf = _epoch_transforms(mi, target, sun_dir[e], obs_dir[e])
        params["sensor.to_world"] = sensor_tf
        params["sun.to_world"] = light_tf
        params.update()
        sums = np.zeros((passes, n_wl))
        img_acc = None
        for k in range(passes):
            s = (seed * 1_000_003 + e * MAX_PASSES + k) % (2**32)
            img = np.asarray(mi.render(scene, seed=s), dtype=float)
            sums[k] = img.sum(axis=(0, 1)) * pixel_area / width
            if e in keep_set:
                img_acc = img if img_acc is None else img_acc + img
        mean[e] = sums.mean(axis=0) * irradiance[e]
        if passes > 1:
            err[e] = sums.std(axis=0, ddof=1) / np.sqrt(passes) * irradiance[e]
        else:
            err[e] = np.nan
        if img_acc is not None:
            images[e] = _image(
                e,
                variant,
                target,
                obs_dir[e],
                resolution_px,
                img_acc / passes / width * irradiance[e],
            )
        if on_epoch is not None:
            on_epoch(1)
    return mean, err, images


def _image(e: int, variant: str, target: Target, obs: F64, res: int, radiance: F64) -> RenderImage:
    """Kept image with a depth map and part indices from orthographic ray casting."""
    from speclight.render.api import make_caster

    centre, radius = target.bounding_sphere()
    origin, direction, pixel_area = primary_rays(centre, radius, obs[None, :], res)
    hits = make_caster(target, variant).intersect(origin, direction)
    depth = (hits.t_m - 2.0 * radius).reshape(res, res)
    right, up = image_axes(obs[None, :])
    return RenderImage(
        e, radiance, depth, hits.part.reshape(res, res), float(np.sqrt(pixel_area)), right[0], up[0]
    )
