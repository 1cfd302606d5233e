"""Reflection stage of the pipeline: the target, the solar spectrum and the rendering."""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from speclight import schema
from speclight.constants import AU_M
from speclight.illumination import solar_irradiance_W_m2_nm
from speclight.render.result import RenderImage
from speclight.render.session import RenderSession
from speclight.scenario import LoadedScenario
from speclight.simulate.geometry_stage import Geometry
from speclight.target import Target, target_from_spec

F64 = NDArray[np.float64]


def build_target(loaded: LoadedScenario) -> Target:
    """The scenario's target (shape and materials) in its body frame."""
    cfg = loaded.scenario.target
    assert cfg is not None
    shape = cfg.shape.model_dump(exclude_none=True)
    if cfg.shape.builtin is not None:
        shape.pop("scale_m_per_unit", None)
    materials = {name: m.model_dump(exclude_none=True) for name, m in cfg.materials.items()}
    return target_from_spec(shape, materials, base_dir=loaded.base_dir)


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
    observable = geo.observable
    sunlit = geo.sunlit_fraction if sc.illumination.sun else np.zeros(n)
    lit = observable & (sunlit > 0)
    intensity[observable & ~lit] = 0.0
    std[observable & ~lit] = 0.0
    idx = np.flatnonzero(lit)
    flags = np.zeros(n, dtype=np.uint8)
    variant = ""
    images: dict[int, RenderImage] = {}
    part_names: list[str] = []
    if idx.size:
        from speclight.render import render_intensity

        keep = [int(np.searchsorted(idx, i)) for i in sc.render.save_images_at if i in set(idx)]
        if target is None:
            target = build_target(loaded)
        if session is None:
            session = RenderSession.create(sc.render.mode, sc.render.variant, target.materials)
        part_names = [part.name for part in target.parts]
        result = render_intensity(
            target,
            geo.sun_direction_body[idx],
            geo.observer_direction_body[idx],
            solar[idx],
            wavelength_nm,
            mode=sc.render.mode,
            resolution_px=sc.render.resolution_px,
            samples_per_pixel=sc.render.samples_per_pixel,
            seed=sc.render.seed,
            variant=sc.render.variant,
            workers=os.cpu_count(),  # used by the numpy fallback; Dr.Jit uses all cores itself
            progress=progress,
            keep_images_for=keep or None,
            on_hits=None if on_hits is None else on_hits(idx),
            solar_disk=sc.illumination.solar_disk,
            session=session,
        )
        scale = sunlit[idx, None]
        intensity[idx] = result.intensity_W_sr_nm * scale
        if result.intensity_std_W_sr_nm is not None:
            std[idx] = result.intensity_std_W_sr_nm * scale
        else:
            std[idx] = 0.0
        failed = idx[~(result.ok & np.all(np.isfinite(result.intensity_W_sr_nm), axis=1))]
        flags[failed] |= schema.FLAG_RENDER_FAILED
        variant = result.variant
        images = {int(idx[k]): image for k, image in result.images.items()}
        for epoch, image in images.items():  # penumbra: as the intensity
            image.radiance_W_m2_sr_nm = image.radiance_W_m2_sr_nm * sunlit[epoch]
    return Reflection(solar, intensity, std, variant, images, part_names, flags)
