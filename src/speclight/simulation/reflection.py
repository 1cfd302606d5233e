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
from speclight.render.result import RenderImage, RenderResult
from speclight.render.session import RenderSession
from speclight.scenario import LoadedScenario
from speclight.scenario.sections_light import (
    Conductor,
    Dielectric,
    ReflectanceFile,
    ReflectancePairs,
    Shape,
    ShippedTable,
)
from speclight.scenario.sections_light import Material as MaterialModel
from speclight.simulation.earthshine_stage import earthshine_intensity
from speclight.simulation.geometry_stage import Geometry, pole_body
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
from speclight.wavelength_grid import bin_widths_nm

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
    return _builtin_target(shape, mats)


def _builtin_target(shape: Shape, mats: dict[str, Material]) -> Target:
    """A built-in shape with the sizes the scenario gives (the others: its defaults)."""
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
        extension=m.extension,
        coefficients=m.coefficients,
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
    flags: NDArray[np.uint16] | None = None
    #: (N, L) the part of the intensity from Earthshine (``illumination.earthshine``).
    earthshine_W_sr_nm: F64 | None = None
    #: (N,) fraction of the reflected sunlight from outside measured tables' support
    #: (``outside_support_fraction``); None where not rendered (a reflectivity map).
    outside_support_fraction: F64 | None = None
    #: (N, L) the part of the Sun's reflection from outside measured tables' support.
    outside_support_W_sr_nm: F64 | None = None
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
            flags=np.zeros(geo.t_s.size, dtype=schema.FLAG_DTYPE),
        )
    sunlit = _sunlit_fraction(loaded, geo)
    lit = geo.observable & (sunlit > 0)
    out = _unrendered(solar, geo.observable & ~lit, wavelength_nm.size, sc.render.polarization)
    idx = np.flatnonzero(lit)
    earthshine_on = _earthshine_on(loaded, geo)
    if not (idx.size or earthshine_on):
        _flag_outside_support(out, wavelength_nm)
        return out
    target = build_target(loaded) if target is None else target
    session = _session(loaded, target) if session is None else session
    if idx.size:
        result = _render_lit(
            loaded, geo, wavelength_nm, solar, idx, progress, on_hits, target, session
        )
        _store_lit(out, result, idx, sunlit)
        out.part_names = [part.name for part in target.parts]
    _flag_outside_support(out, wavelength_nm)  # of the sunlight (Earthshine not counted)
    if earthshine_on:
        _add_earthshine(out, loaded, geo, wavelength_nm, target, session)
    return out


def _sunlit_fraction(loaded: LoadedScenario, geo: Geometry) -> F64:
    """The visible fraction of the solar disk per epoch (0 with ``illumination.sun`` off)."""
    return geo.sunlit_fraction if loaded.scenario.illumination.sun else np.zeros(geo.t_s.size)


def _earthshine_on(loaded: LoadedScenario, geo: Geometry) -> bool:
    """Whether Earthshine is rendered: asked for, and some epoch is observable."""
    return loaded.scenario.illumination.earthshine is not None and bool(np.any(geo.observable))


def _session(loaded: LoadedScenario, target: Target) -> RenderSession:
    """The run's render session (its one Mitsuba variant) for the scenario's target."""
    r = loaded.scenario.render
    return RenderSession.create(r.mode, r.variant, target.materials, r.polarization)


def _unrendered(
    solar: F64, observable_unlit: NDArray[np.bool_], n_wl: int, polarized: bool
) -> Reflection:
    """NaN everywhere (not rendered), 0 at the observable epochs the Sun does not light."""
    n = observable_unlit.size
    shape = (n, n_wl, 3) if polarized else (0,)
    arrays = [np.full((n, n_wl), np.nan), np.full((n, n_wl), np.nan)]
    stokes = [np.full(shape, np.nan), np.full(shape, np.nan)] if polarized else [None, None]
    for a in [*arrays, *stokes]:
        if a is not None:
            a[observable_unlit] = 0.0
    return Reflection(
        solar_irradiance_W_m2_nm=solar,
        intensity_W_sr_nm=arrays[0],
        intensity_std_W_sr_nm=arrays[1],
        flags=np.zeros(n, dtype=schema.FLAG_DTYPE),
        stokes_W_sr_nm=stokes[0],
        stokes_std_W_sr_nm=stokes[1],
    )


def _render_lit(
    loaded: LoadedScenario,
    geo: Geometry,
    wavelength_nm: F64,
    solar: F64,
    idx: NDArray[np.int64],
    progress: bool,
    on_hits: Callable[[NDArray[np.int64]], Callable[..., None]] | None,
    target: Target,
    session: RenderSession,
) -> RenderResult:
    """The render of the lit epochs ``idx`` (articulated parts posed per group of epochs)."""
    sc = loaded.scenario
    assert sc.target is not None
    if progress and sc.render.mode == "path":
        from speclight.simulation.memory import path_render_note

        print(path_render_note(sc, idx.size), file=sys.stderr)  # the bar follows
    common = _render_options(loaded, geo, idx, on_hits, session)
    sun_b, obs_b = geo.sun_direction_body[idx], geo.observer_direction_body[idx]
    joints = build_joints(loaded, target) if sc.target.articulation else ()
    if joints:
        from speclight.render.articulated import render_articulated

        angles = joint_angles_rad(joints, sun_b, geo.time_utc[idx])
        return render_articulated(
            target, joints, angles, sun_b, obs_b, solar[idx], wavelength_nm,
            angle_step_deg=sc.target.articulation_step_deg, **common,
        )  # fmt: skip
    from speclight.render import render_intensity

    return render_intensity(
        target, sun_b, obs_b, solar[idx], wavelength_nm, mode=session.mode,
        variant=sc.render.variant, progress=progress, **common,
    )  # fmt: skip


def _render_options(
    loaded: LoadedScenario,
    geo: Geometry,
    idx: NDArray[np.int64],
    on_hits: Callable[[NDArray[np.int64]], Callable[..., None]] | None,
    session: RenderSession,
) -> dict[str, Any]:
    """The keywords every render of the lit epochs ``idx`` takes from the scenario."""
    sc = loaded.scenario
    keep = [int(np.searchsorted(idx, i)) for i in sc.render.save_images_at if i in set(idx)]
    common: dict[str, Any] = dict(
        resolution_px=sc.render.resolution_px,
        samples_per_pixel=sc.render.samples_per_pixel,
        seed=sc.render.seed,
        workers=os.cpu_count(),  # used by the numpy fallback; Dr.Jit uses all cores itself
        on_hits=None if on_hits is None else on_hits(idx),
        solar_disk=sc.illumination.solar_disk,
        keep_images_for=keep or None,
        session=session,
    )
    if sc.render.polarization:
        common.update(polarization=True, pole_body=pole_body(geo)[idx])
    return common


def _store_lit(out: Reflection, result: RenderResult, idx: NDArray[np.int64], sunlit: F64) -> None:
    """Put the lit epochs' render in ``out``, scaled by the visible fraction of the Sun."""
    assert out.intensity_W_sr_nm is not None and out.intensity_std_W_sr_nm is not None
    scale = sunlit[idx, None]
    out.intensity_W_sr_nm[idx] = result.intensity_W_sr_nm * scale
    if result.intensity_std_W_sr_nm is not None:
        out.intensity_std_W_sr_nm[idx] = result.intensity_std_W_sr_nm * scale
    else:
        out.intensity_std_W_sr_nm[idx] = 0.0
    failed = idx[~(result.ok & np.all(np.isfinite(result.intensity_W_sr_nm), axis=1))]
    assert out.flags is not None
    out.flags[failed] |= schema.FLAG_RENDER_FAILED
    if out.stokes_W_sr_nm is not None and out.stokes_std_W_sr_nm is not None:
        assert result.stokes_W_sr_nm is not None and result.stokes_std_W_sr_nm is not None
        out.stokes_W_sr_nm[idx] = result.stokes_W_sr_nm * scale[:, :, None]
        out.stokes_std_W_sr_nm[idx] = result.stokes_std_W_sr_nm * scale[:, :, None]
    if result.outside_support_W_sr_nm is not None:
        if out.outside_support_W_sr_nm is None:
            out.outside_support_W_sr_nm = np.zeros_like(out.intensity_W_sr_nm)
        out.outside_support_W_sr_nm[idx] = result.outside_support_W_sr_nm * scale
    out.variant = result.variant
    out.images = {int(idx[k]): image for k, image in result.images.items()}
    for epoch, image in out.images.items():  # penumbra: as the intensity
        image.radiance_W_m2_sr_nm = image.radiance_W_m2_sr_nm * sunlit[epoch]


def _flag_outside_support(out: Reflection, wavelength_nm: F64) -> None:
    """Set ``outside_support_fraction`` (the intensity from outside measured tables'
    support over all, integrated over the grid's bins) and its flag bit."""
    assert out.intensity_W_sr_nm is not None and out.flags is not None
    widths = bin_widths_nm(wavelength_nm)
    total = out.intensity_W_sr_nm @ widths
    outside = np.zeros_like(total)
    if out.outside_support_W_sr_nm is not None:
        outside = np.nan_to_num(out.outside_support_W_sr_nm) @ widths
    with np.errstate(invalid="ignore", divide="ignore"):
        fraction = np.where(total > 0, outside / total, np.where(np.isfinite(total), 0.0, np.nan))
    out.outside_support_fraction = fraction
    out.flags[fraction > schema.OUTSIDE_SUPPORT_FLAG_FRACTION] |= schema.FLAG_OUTSIDE_SUPPORT


def _add_earthshine(
    out: Reflection,
    loaded: LoadedScenario,
    geo: Geometry,
    wavelength_nm: F64,
    target: Target,
    session: RenderSession,
) -> None:
    """Add the light of the sunlit Earth (``illumination.earthshine``) to ``out``."""
    earthshine, es_stokes = earthshine_intensity(
        loaded, geo, out.solar_irradiance_W_m2_nm, wavelength_nm, target, session
    )
    out.earthshine_W_sr_nm = earthshine
    assert out.intensity_W_sr_nm is not None
    # NaN rows stay NaN (failed, unseen)
    out.intensity_W_sr_nm = out.intensity_W_sr_nm + np.nan_to_num(earthshine)
    if out.stokes_W_sr_nm is not None and es_stokes is not None:
        out.stokes_W_sr_nm = out.stokes_W_sr_nm + np.nan_to_num(es_stokes)
