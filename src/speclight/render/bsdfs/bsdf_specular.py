"""``specular``: a smooth mirror, reflecting the solar disk.

The single mode shows a pixel the radiance ``F E / Omega_sun`` where the mirror direction of
the view falls inside the solar disk (:func:`speclight.render.shading.mirror_in_sun`); path
mode uses Mitsuba's ``conductor`` (a point Sun never reaches the observer through a mirror:
``illumination.solar_disk`` lights it with the disk).
"""

from __future__ import annotations

from collections.abc import Hashable
from typing import Any

from speclight.render.bsdfs.bsdf_interface import (
    F64,
    MaterialBsdf,
    fresnel_factor,
    fresnel_linear_factor,
)
from speclight.render.bsdfs.bsdf_microfacet import fresnel_path_parameters
from speclight.render.kernel_ops import NUMPY_OPS, ShadingOps
from speclight.render.shading import SUN_SOLID_ANGLE_SR


class SpecularBsdf(MaterialBsdf):
    """One channel: the glint over the Sun's solid angle, times F at the half-phase angle."""

    def mirror_lobe(self) -> bool:
        return True

    def main_weight(
        self,
        cos_i: F64,
        cos_o: F64,
        cos_h: F64,
        cos_d: F64,
        mirror_ok: F64,
        ops: ShadingOps = NUMPY_OPS,
    ) -> F64:
        return mirror_ok / SUN_SOLID_ANGLE_SR

    def kernel_key(self, block: bool = False) -> Hashable:
        return "mirror"  # the reflectance is in the factor

    def main_factor(self, cos_half_phase: F64, wavelength_nm: F64) -> F64:
        return fresnel_factor(self.material.reflectance, cos_half_phase, wavelength_nm)

    def linear_factor(self, cos_half_phase: F64, wavelength_nm: F64) -> F64:
        return fresnel_linear_factor(self.material.reflectance, cos_half_phase, wavelength_nm)

    def path_bsdf(self, lo_nm: float, hi_nm: float, coat: str = "spectral") -> dict[str, Any]:
        refl = self.material.reflectance
        return {"type": "conductor"} | fresnel_path_parameters(refl, lo_nm, hi_nm)
