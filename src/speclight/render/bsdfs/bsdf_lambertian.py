"""``lambertian``: ideal diffuse reflection, f = albedo(lambda) / pi (Lambert 1760)."""

from __future__ import annotations

from collections.abc import Hashable
from typing import Any

import numpy as np

from speclight.render.bsdfs.bsdf_interface import (
    F64,
    MaterialBsdf,
    reflectance_factor,
    reflectance_spectrum,
)
from speclight.render.kernel_ops import NUMPY_OPS, ShadingOps


class LambertianBsdf(MaterialBsdf):
    """One channel: ``cos(theta_i) / pi`` times the albedo; unpolarising."""

    def main_weight(
        self,
        cos_i: F64,
        cos_o: F64,
        cos_h: F64,
        cos_d: F64,
        mirror_ok: F64,
        ops: ShadingOps = NUMPY_OPS,
    ) -> F64:
        return cos_i / np.pi

    def kernel_key(self, block: bool = False) -> Hashable:
        return "lambertian"  # the albedo is in the factor

    def main_factor(self, cos_half_phase: F64, wavelength_nm: F64) -> F64:
        return reflectance_factor(self.material.reflectance, len(cos_half_phase), wavelength_nm)

    def path_bsdf(self, lo_nm: float, hi_nm: float, coat: str = "spectral") -> dict[str, Any]:
        refl = reflectance_spectrum(self.material.reflectance, lo_nm, hi_nm)
        return {"type": "diffuse", "reflectance": refl}
