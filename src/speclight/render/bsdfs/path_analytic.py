"""Path mode's BSDF of the analytic models: a Python ``mi.BSDF`` running the numpy forms.

The forms of :mod:`speclight.target.brdf_fit.analytic_forms` are written against a small set
of array functions (:class:`~speclight.target.brdf_fit.analytic_forms.ArrayOps`); here they
get Dr.Jit's, so path mode evaluates the very functions the single mode and the fits use,
traced by Dr.Jit into the path tracer's kernel. The microfacet lobe takes D and G1 from
Mitsuba's ``MicrofacetDistribution`` (the terms of its ``roughconductor``, which the ``ggx``
and ``beckmann`` models' path mode uses; the contract test holds both modes together).

Sampling (it sets only the noise, not the mean): a mixture of the cosine-weighted hemisphere
and the visible normals of a GGX distribution whose width follows the form's lobe
(:func:`sampling_lobe`); the pdf is that mixture's, so that any lobe is estimated without
bias. As in :mod:`.path_coat`, the class is defined per variant on first use, since
``mi.BSDF`` is the active variant's. Component masks of the BSDF context are not looked at.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from speclight.render.bsdfs.bsdf_interface import F64, irregular_spectrum
from speclight.target.brdf_fit.analytic_forms import ArrayOps
from speclight.target.brdf_fit.form_coefficients import evaluate

_CLASSES: dict[str, Any] = {}
LOG10_2 = float(np.log10(2.0))
LOG2_10 = float(np.log2(10.0))


def sampling_lobe(model: str, c: dict[str, Any]) -> tuple[float, float]:
    """(probability of sampling the lobe, GGX alpha of the sampled lobe) for a form."""
    if model == "phong":
        kd, ks = float(c["kd"]), float(c["ks"])
        share = ks / (kd + ks) if kd + ks > 0 else 0.5
        return float(np.clip(share, 0.1, 0.9)), float(np.clip(np.sqrt(2 / (c["n"] + 2)), 5e-3, 1))
    if model == "microfacet":
        return float(np.clip(1.0 - c["diffuse"], 0.1, 0.9)), float(c["roughness"])
    if model == "abg":  # the knee of the lobe, |beta - beta_0| = B^(1/g)
        return 0.5, float(np.clip(c["b"] ** (1.0 / c["g"]), 5e-3, 1.0))
    return 0.5, 0.1


def analytic_bsdf(
    mi: Any, model: str, coefficients: dict[str, Any], wavelength_nm: F64, ratio: F64
) -> Any:
    """A Mitsuba BSDF object (active variant) of analytic ``model`` with ``coefficients``,
    its BRDF scaled by the spectrum ``ratio`` [1] given at ``wavelength_nm`` [nm]."""
    cls = _CLASSES.get(mi.variant())
    if cls is None:
        cls = _CLASSES[mi.variant()] = _define(mi)
    out = cls(mi.Properties())
    texture = None
    if np.any(ratio != 1.0):
        texture = mi.load_dict(irregular_spectrum(wavelength_nm, ratio))
    out.configure(model, coefficients, texture)
    return out


def _ops(mi: Any, dr: Any) -> ArrayOps:
    class DrJitOps(ArrayOps):
        @staticmethod
        def sqrt(x: Any) -> Any:
            return dr.sqrt(x)

        @staticmethod
        def clip(x: Any, low: float, high: float) -> Any:
            return dr.clip(x, low, high)

        @staticmethod
        def maximum(x: Any, y: Any) -> Any:
            return dr.maximum(x, y)

        @staticmethod
        def minimum(x: Any, y: Any) -> Any:
            return dr.minimum(x, y)

        @staticmethod
        def power(x: Any, y: Any) -> Any:
            return dr.power(x, y)

        @staticmethod
        def log10(x: Any) -> Any:
            return dr.log2(x) * LOG10_2

        @staticmethod
        def exp10(x: Any) -> Any:
            return dr.exp2(x * LOG2_10)

        @staticmethod
        def microfacet(cos_i: Any, cos_o: Any, cos_h: Any, alpha: float, kind: str) -> Any:
            kinds = {"ggx": mi.MicrofacetType.GGX, "beckmann": mi.MicrofacetType.Beckmann}
            distr = mi.MicrofacetDistribution(kinds[kind], alpha, False)

            def up(c: Any) -> Any:  # a direction at angle acos(c) from the normal
                return mi.Vector3f(dr.sqrt(dr.maximum(1.0 - c * c, 0.0)), 0.0, c)

            m = up(cos_h)
            g = distr.smith_g1(up(cos_i), m) * distr.smith_g1(up(cos_o), m)
            return distr.eval(m) * g / (4.0 * dr.maximum(cos_i * cos_o, 1e-12))

    return DrJitOps()


def _define(mi: Any) -> Any:
    import drjit as dr

    ops = _ops(mi, dr)

    class AnalyticPathBsdf(mi.BSDF):
        def __init__(self, props: Any) -> None:
            mi.BSDF.__init__(self, props)

        def configure(self, model: str, coefficients: dict[str, Any], texture: Any) -> None:
            self.model, self.coefficients, self.texture = model, coefficients, texture
            self.p_lobe, alpha = sampling_lobe(model, coefficients)
            self.distr = mi.MicrofacetDistribution(mi.MicrofacetType.GGX, alpha, True)
            lobe = mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.FrontSide
            diffuse = mi.BSDFFlags.DiffuseReflection | mi.BSDFFlags.FrontSide
            self.m_components = [lobe, diffuse]
            self.m_flags = lobe | diffuse

        def _eval_pdf(self, si: Any, wo: Any, active: Any) -> tuple[Any, Any]:
            cos_i, cos_o = mi.Frame3f.cos_theta(si.wi), mi.Frame3f.cos_theta(wo)
            active = active & (cos_i > 0.0) & (cos_o > 0.0)
            h = dr.normalize(si.wi + wo)
            cos_d = dr.clip(dr.dot(si.wi, h), 0.0, 1.0)
            f = evaluate(self.model, self.coefficients, cos_i, cos_o, h.z, cos_d, ops)
            value = mi.Spectrum(f * cos_o)
            if self.texture is not None:
                value = value * self.texture.eval(si, active)
            lobe_pdf = self.distr.pdf(si.wi, h) / (4.0 * dr.maximum(dr.abs(dr.dot(wo, h)), 1e-12))
            pdf = (1.0 - self.p_lobe) * dr.inv_pi * cos_o + self.p_lobe * lobe_pdf
            return dr.select(active, value, 0.0), dr.select(active, pdf, 0.0)

        def eval(self, ctx: Any, si: Any, wo: Any, active: Any = True) -> Any:
            return self._eval_pdf(si, wo, active)[0]

        def pdf(self, ctx: Any, si: Any, wo: Any, active: Any = True) -> Any:
            return self._eval_pdf(si, wo, active)[1]

        def eval_pdf(self, ctx: Any, si: Any, wo: Any, active: Any = True) -> Any:
            return self._eval_pdf(si, wo, active)

        def sample(self, ctx: Any, si: Any, sample1: Any, sample2: Any, active: Any = True) -> Any:
            active = active & (mi.Frame3f.cos_theta(si.wi) > 0.0)
            chose_lobe = sample1 < self.p_lobe
            m, _ = self.distr.sample(si.wi, sample2)
            bs = dr.zeros(mi.BSDFSample3f)
            bs.eta = 1.0
            bs.wo = dr.select(
                chose_lobe, mi.reflect(si.wi, m), mi.warp.square_to_cosine_hemisphere(sample2)
            )
            value, pdf = self._eval_pdf(si, bs.wo, active)
            bs.pdf = pdf
            bs.sampled_type = dr.select(
                chose_lobe,
                mi.UInt32(+mi.BSDFFlags.GlossyReflection),
                mi.UInt32(+mi.BSDFFlags.DiffuseReflection),
            )
            bs.sampled_component = dr.select(chose_lobe, mi.UInt32(0), mi.UInt32(1))
            ok = active & (pdf > 0.0) & (mi.Frame3f.cos_theta(bs.wo) > 0.0)
            return bs, dr.select(ok, value / dr.maximum(pdf, 1e-30), 0.0)

        def traverse(self, callback: Any) -> None:
            return None

        def parameters_changed(self, keys: Any = None) -> None:
            return None

        def to_string(self) -> str:
            return f"AnalyticPathBsdf[{self.model}]"

    return AnalyticPathBsdf
