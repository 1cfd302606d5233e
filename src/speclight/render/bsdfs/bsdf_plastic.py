"""``plastic``: a diffuse base under a transparent dielectric coat, smooth or Beckmann-rough.

Coat reflection F(theta_d; n) (smooth: a mirror reflecting the solar disk; rough: the
Beckmann microfacet lobe) plus the diffuse base, Mitsuba 3's linear ``plastic`` /
``roughplastic`` model f_d = rho_d T(theta_i) T(theta_o) / (n^2 pi (1 - F_dr,int)) (Weidlich
& Wilkie 2007, doi:10.1145/1321261.1321292; the coat's optics in :mod:`.coat_optics`). The
coat's k is ignored (a transparent coat: its real index n). ``rho_d`` is the effective albedo
of the coated base (linear model): a measured diffuse reflectance can be used as is.

The single mode carries the coat in the main channel and bins the base bilinearly in
(cos theta_i, cos theta_o) on :data:`PLASTIC_NODES` nodes per axis: a block of
``PLASTIC_NODES**2`` channels with epoch-independent spectral factors. Path mode renders
the coat with the spectral BSDF of :mod:`.path_coat` (or, ``coat='grouped'``, Mitsuba's own
plugins per group of bins, :mod:`.path_plastic`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from speclight.render.bsdfs.bsdf_interface import (
    F64,
    I64,
    MaterialBsdf,
    finite_cosines,
    fresnel_linear_factor,
    irregular_spectrum,
    spectrum_grid,
)
from speclight.render.bsdfs.coat_optics import coat_transmittance
from speclight.render.bsdfs.path_coat import coat_tables, coated_diffuse
from speclight.render.bsdfs.path_plastic import base_for_mitsuba
from speclight.render.shading import SUN_SOLID_ANGLE_SR
from speclight.target.microfacet_terms import microfacet_weight
from speclight.target.optical_constants import fresnel_reflectance

#: Cosine nodes per axis of the base's (cos theta_i, cos theta_o) binning grid.
PLASTIC_NODES = 33


def plastic_nodes() -> F64:
    """Cosine nodes of the plastic diffuse binning grid."""
    return np.linspace(0.0, 1.0, PLASTIC_NODES)


def bilinear_nodes(cos_i: F64, cos_o: F64) -> tuple[I64, F64]:
    """Flat node indices (P, 4) and weights (P, 4) of points on the (cos_i, cos_o) grid."""
    k = PLASTIC_NODES - 1
    x, y = np.clip(cos_i, 0, 1) * k, np.clip(cos_o, 0, 1) * k
    i0, j0 = np.minimum(x.astype(int), k - 1), np.minimum(y.astype(int), k - 1)
    fx, fy = x - i0, y - j0
    idx = np.stack(
        [
            i0 * (k + 1) + j0,
            (i0 + 1) * (k + 1) + j0,
            i0 * (k + 1) + j0 + 1,
            (i0 + 1) * (k + 1) + j0 + 1,
        ],
        axis=1,
    )
    w = np.stack([(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy], axis=1)
    return idx, w


class PlasticBsdf(MaterialBsdf):
    """The coat in the main channel, the base in a block of binned channels."""

    def mirror_lobe(self) -> bool:
        return self.material.roughness is None  # a smooth coat

    def main_weight(self, cos_i: F64, cos_o: F64, cos_h: F64, cos_d: F64, mirror_ok: F64) -> F64:
        if self.mirror_lobe():
            return mirror_ok / SUN_SOLID_ANGLE_SR
        alpha = float(self.material.roughness or 0.0)
        return microfacet_weight(cos_i, cos_o, cos_h, alpha, "beckmann")

    def main_factor(self, cos_half_phase: F64, wavelength_nm: F64) -> F64:
        eta = self.material.reflectance.eta(wavelength_nm).real
        return fresnel_reflectance(finite_cosines(cos_half_phase)[:, None], eta[None, :])

    def linear_factor(self, cos_half_phase: F64, wavelength_nm: F64) -> F64:
        refl = self.material.reflectance
        return fresnel_linear_factor(refl, cos_half_phase, wavelength_nm, real_index=True)

    def block_size(self) -> int:
        return PLASTIC_NODES**2

    @classmethod
    def planned_block_size(
        cls, given: Mapping[str, Any], resolve: Callable[[str], Path] | None
    ) -> int:
        return PLASTIC_NODES**2

    def block_weights(self, cos_i: F64, cos_o: F64, cos_h: F64, cos_d: F64) -> tuple[I64, I64, F64]:
        idx, bw = bilinear_nodes(cos_i, cos_o)
        rows = np.repeat(np.arange(len(cos_i)), 4)
        return rows, idx.ravel(), (bw * (cos_i / np.pi)[:, None]).ravel()

    def block_factor(self, wavelength_nm: F64) -> F64:
        m = self.material
        assert m.diffuse_reflectance is not None
        eta = m.reflectance.eta(wavelength_nm).real
        t, f_dr = coat_transmittance(plastic_nodes(), eta, m.roughness)  # (K, L), (L,)
        rho = m.diffuse_reflectance.evaluate(wavelength_nm)
        scale = rho / (eta**2 * (1.0 - f_dr))
        return (t[:, None, :] * t[None, :, :] * scale).reshape(-1, len(wavelength_nm))

    def path_bsdf(self, lo_nm: float, hi_nm: float, coat: str = "spectral") -> dict[str, Any]:
        m = self.material
        if coat == "spectral":
            import mitsuba as mi

            return coated_diffuse(mi, coat_tables(m, lo_nm, hi_nm))
        eta = float(np.mean(m.reflectance.eta(spectrum_grid(lo_nm, hi_nm)).real))
        inner = grouped_plastic(self, eta, lo_nm, hi_nm)  # the index is set per group
        if m.roughness is not None:
            inner.update(distribution="beckmann", alpha=float(m.roughness))
        return inner

    def gradient_problem(self) -> str:
        return (
            f"material '{self.material.name}' (plastic): the roughness of a plastic's coat "
            "also sets the transmittance to its diffuse base, a quadrature table without an "
            "analytic derivative here"
        )


def grouped_plastic(bsdf: PlasticBsdf, eta: float, lo_nm: float, hi_nm: float) -> dict[str, Any]:
    """Mitsuba ``plastic`` / ``roughplastic`` (linear) carrying the single mode's model.

    Both use ``f_d = rho T(theta_i) T(theta_o) / (eta^2 pi (1 - F_dr,int))``; Mitsuba's
    F_dr,int estimate (:func:`.path_plastic.mitsuba_internal_reflectance`) differs from the
    exact integral the single mode uses, so the base reflectance handed to Mitsuba is rescaled
    by ``(1 - F_dr,int[Mitsuba]) / (1 - F_dr,int[exact])``, which makes the two equal. The
    coat index is set per group of bins while rendering (:func:`.path_plastic.index_groups`).
    """
    m = bsdf.material
    grid = spectrum_grid(lo_nm, hi_nm)
    return {
        "type": "plastic" if m.roughness is None else "roughplastic",
        "int_ior": eta,
        "ext_ior": 1.0,
        "diffuse_reflectance": irregular_spectrum(grid, base_for_mitsuba(m, eta, grid)),
        "nonlinear": False,
    }
