"""Render stage: radiant intensity of the target toward the observer, per wavelength.

Mitsuba and Dr.Jit are imported lazily, only inside this subpackage, when a render runs.
"""

from speclight.render.api import material_contributions, render_intensity
from speclight.render.laser_returns import LaserLight, LaserReturns, render_laser_returns
from speclight.render.result import RenderImage, RenderResult
from speclight.render.session import RenderMode, RenderSession
from speclight.render.variant import (
    available_variants,
    choose_variant,
    engine_versions,
    find_libllvm,
)

__all__ = [
    "LaserLight",
    "LaserReturns",
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
    "render_laser_returns",
]
