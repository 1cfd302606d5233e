"""Path-traced render: multi-bounce Monte Carlo with Mitsuba 3's spectral ``path`` integrator.

Scene: the target's parts with two-sided BSDFs (``diffuse``; ``roughconductor`` with the
Beckmann or GGX distribution, Fresnel from n,k, or a reflectance with ``material='none'``,
i.e. F = 1 scaled by the reflectance; smooth ``conductor``; ``plastic`` / ``roughplastic``
carrying the single mode's plastic model (see :func:`_plastic`, :func:`index_groups`), a
``directional`` Sun of unit spectral irradiance over the whole grid or, with ``solar_disk``,
a far sphere emitter subtending the solar disk (:func:`_sun`; spectra given explicitly: a
bare float would be multiplied by the D65 illuminant), and an ``orthographic``
sensor along the line of sight whose
``specfilm`` has one box response per wavelength bin. Each pixel of channel k holds the
radiance integrated over bin k; dividing by the bin width gives the bin-averaged radiance,
which is scaled by the epoch's solar spectrum (bin averages) afterwards.

The sample budget is split in ``K`` passes with independent seeds; their spread gives the
standard error of the mean per bin. Measured lab BRDF tables are not available in this mode;
RGL ``.bsdf`` measured materials use Mitsuba's ``measured`` plugin (:mod:`.rgl`).
A smooth mirror (``specular``, smooth plastic coat) lit by the directional (point) Sun
reflects no light toward a given observer (a delta BSDF meets a delta light); with
``solar_disk`` it shows its glint. Flat mirrors then glint with little noise (every sample
of the face reaches the disk); a curved mirror's glint covers ~theta_sun^2 / 4 of its image
(4e-6 for a sphere), so it needs ~1e7 samples per epoch for 10 % noise.

Reference: Jakob et al., Mitsuba 3 renderer, https://mitsuba-renderer.org (2022);
Veach 1997, Robust Monte Carlo methods for light transport simulation, PhD thesis, Stanford.
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.render import material_channels as channels
from speclight.render.camera import image_axes, primary_rays
from speclight.render.path_plastic import base_for_mitsuba, group_bases, index_groups
from speclight.render.raycast import Caster
from speclight.render.result import RenderImage
from speclight.render.rgl import is_rgl, path_bsdf
from speclight.target.materials import Material
from speclight.target.parts import Target
from speclight.target.reflectance import Reflectance
from speclight.wavelength_grid import grid_bin_bounds_nm

if TYPE_CHECKING:
    from speclight.render.session import RenderSession

F64 = NDArray[np.float64]
#: Longest path (number of bounces + 1) followed; Russian roulette starts after 5.
MAX_DEPTH = 16
MAX_PASSES = 8
#: Distance of the solar-disk sphere from the target's centre, in bounding radii: the
#: direction to the Sun varies across the target by < 1 / SUN_DISTANCE_FACTOR rad (1e-5 rad
#: against a disk radius of 4.65e-3 rad).
SUN_DISTANCE_FACTOR = 1.0e5


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
        inner = _plastic(m, float(np.mean(refl.eta(grid).real)), lo, hi)  # set per group
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


def _plastic(m: Material, eta: float, lo: float, hi: float) -> dict[str, Any]:
    """Mitsuba ``plastic`` / ``roughplastic`` (linear) carrying the single mode's model.

    Both use ``f_d = rho T(theta_i) T(theta_o) / (eta^2 pi (1 - F_dr,int))``; Mitsuba's
    F_dr,int estimate (:func:`.path_plastic.mitsuba_internal_reflectance`) differs from the
    exact integral the single mode uses, so the base reflectance handed to Mitsuba is rescaled
    by ``(1 - F_dr,int[Mitsuba]) / (1 - F_dr,int[exact])``, which makes the two equal. The
    coat index is set per group of bins while rendering (:func:`.path_plastic.index_groups`).
    """
    grid = np.linspace(lo, hi, max(2, int((hi - lo) / 2.0) + 1))
    inner: dict[str, Any] = {
        "type": "plastic" if m.roughness is None else "roughplastic",
        "int_ior": eta,
        "ext_ior": 1.0,
        "diffuse_reflectance": _spectrum(grid, base_for_mitsuba(m, eta, grid)),
        "nonlinear": False,
    }
    return inner


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
    radiance = 1.0 / (np.pi * channels.sun_disk_sin2())
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
    r = dist * np.sqrt(channels.sun_disk_sin2())
    return mi.ScalarTransform4f().translate(pos.tolist()) @ mi.ScalarTransform4f().scale([r, r, r])


def build_scene(
    target: Target,
    edges_lo: F64,
    edges_hi: F64,
    resolution_px: int,
    spp: int,
    solar_disk: bool = False,
    groups: list[tuple[int, int]] | None = None,
) -> tuple[Any, Any]:
    """Mitsuba scene and its parameters (``sensor{j}.to_world``, ``sun.to_world`` are updated).

    One orthographic sensor per group of bins (``groups``: (first, end) bin indices; all
    bins in one group by default), its ``specfilm`` holding that group's bins.
    """
    import mitsuba as mi

    lo, hi = float(edges_lo[0]), float(edges_hi[-1])
    scene: dict[str, Any] = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": MAX_DEPTH, "hide_emitters": True},
        "sun": _sun(lo, hi, solar_disk),
    }
    for j, (a, b) in enumerate(groups or [(0, len(edges_lo))]):
        bands = {
            f"band{k:04d}": {
                "type": "regular",
                "wavelength_min": float(edges_lo[k]),
                "wavelength_max": float(edges_hi[k]),
                "values": "1, 1",
            }
            for k in range(a, b)
        }
        scene[f"sensor{j}"] = {
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
    return loaded, mi.traverse(loaded)


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


def render_path(
    target: Target,
    sun_dir: F64,
    obs_dir: F64,
    irradiance: F64,
    wavelength_nm: F64,
    session: RenderSession,
    resolution_px: int,
    samples_per_pixel: int,
    seed: int,
    keep: Iterable[int] = (),
    on_epoch: Callable[[int], None] | None = None,
    solar_disk: bool = False,
) -> tuple[F64, F64, dict[int, RenderImage]]:
    """Intensity (N, L), its standard error (N, L) [W sr-1 nm-1] and kept images.

    ``session``: the run's render session (its spectral variant; its ray caster gives the
    kept images' depth maps and part indices).

    ``solar_disk``: light the target with the finite solar disk (:func:`_sun`) instead of a
    point (directional) Sun, so that smooth mirrors and smooth plastic coats show their glint.
    """
    mi = session.activate()  # a *_spectral variant (RenderSession.create checks it)
    # A single wavelength is rendered as a 1 nm wide bin around it.
    lo, hi = grid_bin_bounds_nm(wavelength_nm)
    width = hi - lo
    passes = max(1, min(MAX_PASSES, samples_per_pixel))
    spp = max(1, samples_per_pixel // passes)
    groups = index_groups(target, wavelength_nm)
    spans = [(a, b) for a, b, _ in groups]
    scene, params = build_scene(target, lo, hi, resolution_px, spp, solar_disk, spans)
    # Each group gets its share of the samples (>= 1 spp): the samples per bin, hence the
    # noise per bin, are those of one render over all bins.
    group_spp = [max(1, round(spp * (b - a) / len(wavelength_nm))) for a, b in spans]
    grid = np.linspace(lo[0], hi[-1], max(2, int((hi[-1] - lo[0]) / 2.0) + 1))
    sensors = {sen.id(): sen for sen in scene.sensors()}
    bases = group_bases(target, groups, grid)
    _, radius = target.bounding_sphere()
    pixel_area = (2.0 * radius / resolution_px) ** 2
    n_ep, n_wl = len(sun_dir), len(wavelength_nm)
    sums = np.zeros((n_ep, passes, n_wl))
    acc = {e: np.zeros((resolution_px, resolution_px, n_wl)) for e in set(keep)}
    # Groups outer: Mitsuba recomputes its coat tables (~0.1 s) only once per group.
    for j, (a, b, etas) in enumerate(groups):
        for k, n in etas.items():
            params[f"part{k}.bsdf.brdf_0.eta"] = n
            params[f"part{k}.bsdf.brdf_0.diffuse_reflectance.values"] = bases[j][k]
        for e in range(n_ep):
            sensor_tf, light_tf = _epoch_transforms(mi, target, sun_dir[e], obs_dir[e], solar_disk)
            params[f"sensor{j}.to_world"] = sensor_tf
            params["sun.to_world"] = light_tf
            params.update()
            for k in range(passes):
                s = (seed * 1_000_003 + e * MAX_PASSES + k + j * 7_919) % (2**32)
                img = mi.render(scene, sensor=sensors[f"sensor{j}"], seed=s, spp=group_spp[j])
                img = np.asarray(img, dtype=float)
                sums[e, k, a:b] = img.sum(axis=(0, 1)) * pixel_area / width[a:b]
                if e in acc:
                    acc[e][:, :, a:b] += img
            if on_epoch is not None and j == len(groups) - 1:
                on_epoch(1)
    mean = sums.mean(axis=1) * irradiance
    if passes > 1:
        err = sums.std(axis=1, ddof=1) / np.sqrt(passes) * irradiance
    else:
        err = np.full((n_ep, n_wl), np.nan)
    images = {
        e: _image(
            e,
            session.caster(target),
            target,
            obs_dir[e],
            resolution_px,
            a_e / passes / width * irradiance[e],
        )
        for e, a_e in acc.items()
    }
    return mean, err, images


def _image(
    e: int, caster: Caster, target: Target, obs: F64, res: int, radiance: F64
) -> RenderImage:
    """Kept image with a depth map and part indices from orthographic ray casting."""
    centre, radius = target.bounding_sphere()
    origin, direction, pixel_area = primary_rays(centre, radius, obs[None, :], res)
    hits = caster.intersect(origin, direction)
    depth = (hits.t_m - 2.0 * radius).reshape(res, res)
    right, up = image_axes(obs[None, :])
    return RenderImage(
        e, radiance, depth, hits.part.reshape(res, res), float(np.sqrt(pixel_area)), right[0], up[0]
    )
