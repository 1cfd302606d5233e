"""Reflection stage of the pipeline: the target, the solar spectrum and the rendering."""

from __future__ import annotations

import os
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight import schema
from speclight.constants import AU_M
from speclight.illumination import solar_irradiance_W_m2_nm
from speclight.render.result import RenderImage
from speclight.render.session import RenderSession
from speclight.scenario import LoadedScenario
from speclight.scenario.sections_light import (
    Conductor,
    Dielectric,
    ReflectanceFile,
    ReflectancePairs,
    ShippedTable,
)
from speclight.scenario.sections_light import Material as MaterialModel
from speclight.simulate.earthshine_stage import earthshine_intensity
from speclight.simulate.geometry_stage import Geometry, pole_body
from speclight.target import Material, Reflectance, Target
from speclight.target.articulation import (
    Joint,
    check_joint_parts,
    joint_angles_rad,
    read_angle_table,
)
from speclight.target.bsdf_models import bsdf_file_parameters
from speclight.target.from_values import BUILTIN_SHAPES
from speclight.target.material_tables import material_table_path
from speclight.target.mesh_io import load_mesh

F64 = NDArray[np.float64]


def build_target(loaded: LoadedScenario) -> Target:
    """The scenario's target (shape and materials) in its body frame.

    Built from the validated scenario models (``target.shape``, ``target.materials``): the
    scenario layer has already checked every key, size and name, so nothing is re-checked.
    """
    cfg = loaded.scenario.target
    assert cfg is not None
    mats = {name: _material(loaded, name, m) for name, m in cfg.materials.items()}
    shape = cfg.shape
    if shape.mesh_file is not None:
        files = [shape.mesh_file] if isinstance(shape.mesh_file, str) else shape.mesh_file
        paths = [loaded.resolve(f) for f in files]
        return load_mesh(paths, mats, scale_m_per_unit=float(shape.scale_m_per_unit))
    assert shape.builtin is not None
    builder, sizes = BUILTIN_SHAPES[shape.builtin]
    kwargs = {k: getattr(shape, k) for k in sizes if getattr(shape, k) is not None}
    kwargs = {k: tuple(v) if isinstance(v, list) else v for k, v in kwargs.items()}
    return builder(materials=mats, **kwargs)  # type: ignore[operator]


def build_joints(loaded: LoadedScenario, target: Target) -> tuple[Joint, ...]:
    """The articulated parts of the scenario's target (``target.articulation``), checked."""
    cfg = loaded.scenario.target
    assert cfg is not None
    joints = []
    for part, j in cfg.articulation.items():
        times = angles = None
        if j.table_file is not None:
            field = f"target.articulation.{part}.table_file"
            times, angles = read_angle_table(loaded.resolve(j.table_file), field)
        joints.append(
            Joint(
                part=part,
                axis=tuple(j.axis),  # type: ignore[arg-type]
                hinge_point_m=tuple(j.hinge_point_m),  # type: ignore[arg-type]
                normal=tuple(j.normal),  # type: ignore[arg-type]
                mode=j.mode,
                table_times_utc=times,
                table_angle_deg=angles,
            )
        )
    check_joint_parts(target, tuple(joints))
    return tuple(joints)


def _reflectance(loaded: LoadedScenario, spec: Any, field: str) -> Reflectance:
    """A :class:`Reflectance` from a validated scenario reflectance (number or model)."""
    if isinstance(spec, ReflectanceFile):
        return Reflectance.table_file(loaded.resolve(spec.file), field=field)
    if isinstance(spec, ShippedTable):
        return Reflectance.table_file(material_table_path(spec.table), field=field)
    if isinstance(spec, ReflectancePairs):
        return Reflectance.pairs(spec.wavelength_nm, spec.value, field=field)
    if isinstance(spec, Conductor):
        return Reflectance.conductor(spec.conductor)
    if isinstance(spec, Dielectric):
        return Reflectance.dielectric(spec.dielectric)
    return Reflectance.constant(float(spec), field=field)


def _material(loaded: LoadedScenario, name: str, m: MaterialModel) -> Material:
    """A scenario material as a :class:`Material` (files named relative to the scenario)."""
    field = f"target.materials.{name}"
    files = {
        key: str(loaded.resolve(value)) if Path(value).suffix else value  # not a shipped name
        for key in bsdf_file_parameters()
        if (value := getattr(m, key))
    }
    diffuse = m.diffuse_reflectance
    return Material(
        name=name,
        bsdf=m.bsdf,
        reflectance=_reflectance(loaded, m.reflectance, f"{field}.reflectance"),
        roughness=None if m.roughness is None else float(m.roughness),
        diffuse_reflectance=None
        if diffuse is None
        else _reflectance(loaded, diffuse, f"{field}.diffuse_reflectance"),
        **files,
    )


@dataclass
class Reflection:
    """Solar irradiance at the target and the target's radiant intensity."""

    solar_irradiance_W_m2_nm: F64
    intensity_W_sr_nm: F64 | None
    intensity_std_W_sr_nm: F64 | None = None
    variant: str = ""
    images: dict[int, RenderImage] = field(default_factory=dict)
    part_names: list[str] = field(default_factory=list)
    #: (N,) flag bits set by this stage (:data:`~speclight.schema.FLAG_RENDER_FAILED`).
    flags: NDArray[np.uint8] | None = None
    #: (N, L) the part of the intensity from Earthshine (``illumination.earthshine``).
    earthshine_W_sr_nm: F64 | None = None
    #: (N, L, 3) Stokes Q, U, V of the intensity in the sky's north-east frame, and their
    #: standard errors (``render.polarization``; :mod:`speclight.render.polarization`).
    stokes_W_sr_nm: F64 | None = None
    stokes_std_W_sr_nm: F64 | None = None


def render_reflection(
    loaded: LoadedScenario,
    geo: Geometry,
    wavelength_nm: F64,
    progress: bool = False,
    on_hits: Callable[[NDArray[np.int64]], Callable[..., None]] | None = None,
    target: Target | None = None,
    session: RenderSession | None = None,
) -> Reflection:
    """Render the sunlit, observable epochs; unlit epochs get 0, unobservable ones NaN.

    Epochs in the Earth's penumbra are rendered with the full Sun and scaled by the visible
    fraction of the solar disk. ``on_hits(epochs)`` gives a callback that sees the render's
    primary ray hits (laser ranging reuses them). ``target`` and ``session``: the run's target
    and render session (built here from the scenario when not given).
    """
    sc = loaded.scenario
    solar = solar_irradiance_W_m2_nm(wavelength_nm, geo.sun_distance_m / AU_M)
    if sc.target is None:
        return Reflection(
            solar_irradiance_W_m2_nm=solar,
            intensity_W_sr_nm=None,
            flags=np.zeros(geo.t_s.size, dtype=np.uint8),
        )
    n, n_wl = geo.t_s.size, wavelength_nm.size
    intensity = np.full((n, n_wl), np.nan)
    std = np.full((n, n_wl), np.nan)
    polarized = sc.render.polarization
    stokes = np.full((n, n_wl, 3), np.nan) if polarized else None
    stokes_std = np.full((n, n_wl, 3), np.nan) if polarized else None
    observable = geo.observable
    sunlit = geo.sunlit_fraction if sc.illumination.sun else np.zeros(n)
    lit = observable & (sunlit > 0)
    intensity[observable & ~lit] = 0.0
    std[observable & ~lit] = 0.0
    if stokes is not None and stokes_std is not None:
        stokes[observable & ~lit] = 0.0
        stokes_std[observable & ~lit] = 0.0
    idx = np.flatnonzero(lit)
    flags = np.zeros(n, dtype=np.uint8)
    variant = ""
    images: dict[int, RenderImage] = {}
    part_names: list[str] = []
    earthshine_on = sc.illumination.earthshine is not None and bool(np.any(observable))
    if idx.size or earthshine_on:
        if target is None:
            target = build_target(loaded)
        if session is None:
            session = RenderSession.create(
                sc.render.mode, sc.render.variant, target.materials, sc.render.polarization
            )
    if idx.size:
        from speclight.render import render_intensity

        assert target is not None and session is not None

        keep = [int(np.searchsorted(idx, i)) for i in sc.render.save_images_at if i in set(idx)]
        part_names = [part.name for part in target.parts]
        if progress and sc.render.mode == "path":
            from speclight.simulate.memory import path_render_note

            print(path_render_note(sc, idx.size), file=sys.stderr)  # the bar follows
        common: dict[str, Any] = dict(
            resolution_px=sc.render.resolution_px,
            samples_per_pixel=sc.render.samples_per_pixel,
            seed=sc.render.seed,
            workers=os.cpu_count(),  # used by the numpy fallback; Dr.Jit uses all cores itself
            on_hits=None if on_hits is None else on_hits(idx),
            solar_disk=sc.illumination.solar_disk,
        )
        if polarized:
            common.update(polarization=True, pole_body=pole_body(geo)[idx])
        sun_b, obs_b = geo.sun_direction_body[idx], geo.observer_direction_body[idx]
        joints = build_joints(loaded, target) if sc.target.articulation else ()
        if joints:
            from speclight.render.articulated import render_articulated

            angles = joint_angles_rad(joints, sun_b, geo.time_utc[idx])
            result = render_articulated(
                target,
                joints,
                angles,
                sun_b,
                obs_b,
                solar[idx],
                wavelength_nm,
                session=session,
                angle_step_deg=sc.target.articulation_step_deg,
                keep_images_for=keep or None,
                **common,
            )
        else:
            result = render_intensity(
                target,
                sun_b,
                obs_b,
                solar[idx],
                wavelength_nm,
                mode=session.mode,
                variant=sc.render.variant,
                progress=progress,
                keep_images_for=keep or None,
                session=session,
                **common,
            )
        scale = sunlit[idx, None]
        intensity[idx] = result.intensity_W_sr_nm * scale
        if result.intensity_std_W_sr_nm is not None:
            std[idx] = result.intensity_std_W_sr_nm * scale
        else:
            std[idx] = 0.0
        failed = idx[~(result.ok & np.all(np.isfinite(result.intensity_W_sr_nm), axis=1))]
        flags[failed] |= schema.FLAG_RENDER_FAILED
        if stokes is not None and stokes_std is not None:
            assert result.stokes_W_sr_nm is not None and result.stokes_std_W_sr_nm is not None
            stokes[idx] = result.stokes_W_sr_nm * scale[:, :, None]
            stokes_std[idx] = result.stokes_std_W_sr_nm * scale[:, :, None]
        variant = result.variant
        images = {int(idx[k]): image for k, image in result.images.items()}
        for epoch, image in images.items():  # penumbra: as the intensity
            image.radiance_W_m2_sr_nm = image.radiance_W_m2_sr_nm * sunlit[epoch]
    earthshine = None
    if earthshine_on:
        assert target is not None and session is not None
        earthshine, es_stokes = earthshine_intensity(
            loaded, geo, solar, wavelength_nm, target, session
        )
        intensity = intensity + np.nan_to_num(earthshine)  # NaN rows stay NaN (failed, unseen)
        if stokes is not None and es_stokes is not None:
            stokes = stokes + np.nan_to_num(es_stokes)
    return Reflection(
        solar, intensity, std, variant, images, part_names, flags, earthshine, stokes, stokes_std
    )
