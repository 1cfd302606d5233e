"""Render stage: radiant intensity of the target toward the observer, per wavelength.

Mitsuba and Dr.Jit are imported lazily, only inside this subpackage, when a render runs.
"""

from speclight.render.api import RenderMode, render_intensity
from speclight.render.result import RenderImage, RenderResult
from speclight.render.variant import (
    available_variants,
    choose_variant,
    engine_versions,
    find_libllvm,
)

__all__ = [
    "RenderImage",
    "RenderMode",
    "RenderResult",
    "available_variants",
    "choose_variant",
    "engine_versions",
    "find_libllvm",
    "render_intensity",
]
