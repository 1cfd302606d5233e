"""``phong``, ``abg``, ``binomial``, ``microfacet``: analytic models fitted to measured tables.

The forms are those of :mod:`speclight.target.brdf_fit.analytic_forms` (one numpy function
each, shared with ``speclight brdf-fit``); the single mode evaluates them per pixel, path mode
runs the same functions on Dr.Jit arrays inside a Python ``mi.BSDF``
(:mod:`.path_analytic`). The material's ``reflectance`` scales the BRDF by
``R(lambda) / R(coefficients.wavelength_nm)`` (1 for a constant: grey, as fitted). They hold
intensity only (no polarisation model).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from speclight.render.bsdfs.bsdf_interface import (
    F64,
    MaterialBsdf,
    normalised_reflectance,
    spectrum_grid,
)
from speclight.target.brdf_fit.form_coefficients import evaluate


class AnalyticBsdf(MaterialBsdf):
    """One channel: ``f cos_i`` of the form times the reflectance ratio."""

    @property
    def coefficients(self) -> dict[str, Any]:
        c = self.material.coefficients
        assert c is not None  # the registry requires them
        return dict(c)

    def main_weight(self, cos_i: F64, cos_o: F64, cos_h: F64, cos_d: F64, mirror_ok: F64) -> F64:
        f = evaluate(self.material.bsdf, self.coefficients, cos_i, cos_o, cos_h, cos_d)
        return np.asarray(f * cos_i, dtype=float)

    def spectral_ratio(self, wavelength_nm: F64) -> F64:
        """``R(lambda) / R(coefficients.wavelength_nm)`` (L,) [1]."""
        m = self.material
        reference = float(self.coefficients.get("wavelength_nm", np.nan))
        return normalised_reflectance(
            m.reflectance, reference, wavelength_nm, f"target.materials.{m.name}"
        )

    def main_factor(self, cos_half_phase: F64, wavelength_nm: F64) -> F64:
        ratio = self.spectral_ratio(wavelength_nm)
        return np.broadcast_to(ratio[None, :], (len(cos_half_phase), len(wavelength_nm)))

    def path_bsdf(self, lo_nm: float, hi_nm: float, coat: str = "spectral") -> Any:
        import mitsuba as mi

        from speclight.render.bsdfs.path_analytic import analytic_bsdf

        grid = spectrum_grid(lo_nm, hi_nm)
        ratio = self.spectral_ratio(grid)
        return analytic_bsdf(mi, self.material.bsdf, self.coefficients, grid, ratio)
