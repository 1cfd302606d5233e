"""``beckmann``, ``ggx``: rough conductors and dielectrics, Cook-Torrance microfacets.

f = F(theta_d) D(h) G1(i) G1(o) / (4 cos_i cos_o) with the Beckmann or GGX normal
distribution and the separable Smith masking (Walter et al. 2007, "Microfacet models for
refraction through rough surfaces", doi:10.2312/EGWR/EGSR07/195-206; the terms in
:mod:`speclight.target.microfacet_terms`), as Mitsuba 3's ``roughconductor``, which path mode
uses. The Fresnel term F is that of the material's n, k at the half-phase angle, or F = 1
scaled by a reflectance given as numbers (Mitsuba's ``material='none'``).
"""

from __future__ import annotations

from typing import Any, Literal, cast

import numpy as np

from speclight.render.brdf_gradient import microfacet_weight_dalpha
from speclight.render.bsdfs.bsdf_interface import (
    F64,
    MaterialBsdf,
    fresnel_factor,
    fresnel_linear_factor,
    irregular_spectrum,
    reflectance_spectrum,
    spectrum_grid,
)
from speclight.target.microfacet_terms import microfacet_weight
from speclight.target.reflectance import Reflectance

Distribution = Literal["beckmann", "ggx"]


def fresnel_path_parameters(refl: Reflectance, lo_nm: float, hi_nm: float) -> dict[str, Any]:
    """Mitsuba conductor parameters of a reflectance: its n, k, or ``material='none'`` with
    the reflectance as ``specular_reflectance`` (F = 1 scaled by it)."""
    if not refl.is_fresnel:
        return {
            "material": "none",
            "specular_reflectance": reflectance_spectrum(refl, lo_nm, hi_nm),
        }
    grid = spectrum_grid(lo_nm, hi_nm)
    eta = refl.eta(grid)
    # an all-zero irregular spectrum is refused by Mitsuba ("no probability mass"):
    # a dielectric without absorption (k = 0) gets the constant 0
    k = irregular_spectrum(grid, eta.imag) if np.any(eta.imag != 0) else 0.0
    return {"eta": irregular_spectrum(grid, eta.real), "k": k}


class MicrofacetBsdf(MaterialBsdf):
    """One channel: ``D G / (4 cos_o)`` times F at the half-phase angle."""

    @property
    def distribution(self) -> Distribution:
        return cast(Distribution, self.material.bsdf)

    @property
    def alpha(self) -> float:
        return float(self.material.roughness or 0.0)

    def main_weight(self, cos_i: F64, cos_o: F64, cos_h: F64, cos_d: F64, mirror_ok: F64) -> F64:
        return microfacet_weight(cos_i, cos_o, cos_h, self.alpha, self.distribution)

    def main_factor(self, cos_half_phase: F64, wavelength_nm: F64) -> F64:
        return fresnel_factor(self.material.reflectance, cos_half_phase, wavelength_nm)

    def linear_factor(self, cos_half_phase: F64, wavelength_nm: F64) -> F64:
        return fresnel_linear_factor(self.material.reflectance, cos_half_phase, wavelength_nm)

    def path_bsdf(self, lo_nm: float, hi_nm: float, coat: str = "spectral") -> dict[str, Any]:
        inner: dict[str, Any] = {
            "type": "roughconductor",
            "distribution": self.distribution,
            "alpha": self.alpha,
        }
        return inner | fresnel_path_parameters(self.material.reflectance, lo_nm, hi_nm)

    def roughness_derivative(self, cos_i: F64, cos_o: F64, cos_h: F64) -> F64 | None:
        if not self.material.roughness:
            return None
        return microfacet_weight_dalpha(cos_i, cos_o, cos_h, self.alpha, self.distribution)

    def gradient_problem(self) -> str:
        return "" if self.material.roughness else super().gradient_problem()
