"""Render stage: radiant intensity of the target toward the observer, per wavelength.

Mitsuba and Dr.Jit are imported lazily, only inside this subpackage, when a render runs.
"""

from speclight.render.api import material_contributions, render_intensity
from speclight.render.result import RenderImage, RenderResult
from speclight.render.session import RenderMode, RenderSession
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
    "RenderSession",
    "available_variants",
    "choose_variant",
    "engine_versions",
    "find_libllvm",
    "material_contributions",
    "render_intensity",
]
