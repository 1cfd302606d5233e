"""A coated-diffuse BSDF for Mitsuba 3 whose coat index varies with wavelength.

Mitsuba's ``plastic`` / ``roughplastic`` take one real coat index, so path mode used to
render plastic materials in ~26 groups of bins, each with its own index (~200 renders per
epoch on the box-wing). This BSDF carries the single mode's plastic model
(:mod:`.bsdf_plastic`) at every sampled wavelength, so the whole
spectrum renders in one pass:

* coat reflection F(theta; n(lambda)): a mirror (smooth coat) or the Beckmann microfacet lobe
  F(i.h) D(h) G1(i) G1(o) / (4 cos_i cos_o) (rough coat; Walter et al. 2007,
  doi:10.2312/EGWR/EGSR07/195-206, separable Smith G as in the single mode);
* the diffuse base rho_d T(theta_i) T(theta_o) / (n^2 pi (1 - F_dr,int)) (Weidlich & Wilkie
  2007, doi:10.1145/1321261.1321292; Mitsuba's linear ``plastic`` model), with the exact
  F_dr,int and, for a rough coat, the transmittance tables of
  :func:`~speclight.render.bsdfs.coat_optics.coat_transmittance` (cached on disk).

The spectral quantities are tabulated on a uniform wavelength grid (:data:`TABLE_STEP_NM`)
and interpolated linearly at the sampled wavelengths; the rough-coat transmittance also
linearly between its cosine nodes, as in the single mode. Written as a Python ``mi.BSDF``:
Dr.Jit traces it into the same kernel as Mitsuba's own plugins. The class is defined per
variant on first use (:func:`coated_diffuse`), since ``mi.BSDF`` is the active variant's.
Component masks of the BSDF context are not looked at (the path integrator asks for all).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.render.bsdfs import coat_optics
from speclight.target.materials import Material

F64 = NDArray[np.float64]
#: Wavelength step of the BSDF's spectral tables [nm]: n(lambda) of the shipped dielectrics
#: is smooth on this scale (linear interpolation error of the coat Fresnel < 1e-5).
TABLE_STEP_NM = 1.0
_CLASSES: dict[str, Any] = {}


def coat_tables(m: Material, lo_nm: float, hi_nm: float) -> dict[str, Any]:
    """Spectral tables of a plastic material on a uniform grid over [lo_nm, hi_nm].

    Returns the grid start and step [nm], the coat index ``eta`` (L,), the base factor
    ``base`` (L,) = rho_d / (n^2 pi (1 - F_dr,int)) [sr-1], and for a rough coat the
    transmittance ``t`` (COAT_TABLE_NODES, L) at :func:`~.coat_optics.coat_table_nodes`.
    """
    assert m.diffuse_reflectance is not None
    n = max(2, int(np.ceil((hi_nm - lo_nm) / TABLE_STEP_NM)) + 1)
    grid = np.linspace(lo_nm, hi_nm, n)
    eta = m.reflectance.eta(grid).real
    t, f_dr = coat_optics.coat_transmittance(coat_optics.coat_table_nodes(), eta, m.roughness)
    base = m.diffuse_reflectance.evaluate(grid) / (eta**2 * np.pi * (1.0 - f_dr))
    out: dict[str, Any] = {
        "start_nm": float(grid[0]),
        "step_nm": float(grid[1] - grid[0]),
        "eta": eta,
        "base": base,
        "roughness": m.roughness,
        "mean_albedo": float(np.mean(m.diffuse_reflectance.evaluate(grid))),
    }
    if m.roughness is not None:
        out["t"] = t
    return out


def coated_diffuse(mi: Any, tables: dict[str, Any]) -> Any:
    """A Mitsuba BSDF object (active variant) of the coated diffuse model with ``tables``."""
    cls = _CLASSES.get(mi.variant())
    if cls is None:
        cls = _CLASSES[mi.variant()] = _define(mi)
    bsdf = cls(mi.Properties())
    bsdf.configure(tables)
    return bsdf


def _define(mi: Any) -> Any:
    import drjit as dr

    n_spec = dr.size_v(mi.Spectrum)
    n_nodes = coat_optics.COAT_TABLE_NODES

    def per_wavelength(fn: Any, lam: Any) -> Any:
        return mi.Spectrum(*[fn(lam[k]) for k in range(n_spec)])

    def fresnel(c: Any, eta: Any) -> Any:
        """Unpolarised Fresnel reflectance, real relative index eta > 1 seen from outside."""
        c = dr.clip(c, 0.0, 1.0)
        s2 = (1.0 - c * c) / (eta * eta)
        ct = dr.sqrt(dr.maximum(1.0 - s2, 0.0))
        rs = (c - eta * ct) / dr.maximum(c + eta * ct, 1e-30)
        rp = (eta * c - ct) / dr.maximum(eta * c + ct, 1e-30)
        return 0.5 * (rs * rs + rp * rp)

    def mean(s: Any) -> Any:
        return sum(s[k] for k in range(n_spec)) / n_spec

    class CoatedDiffuse(mi.BSDF):
        def __init__(self, props: Any) -> None:
            mi.BSDF.__init__(self, props)

        def configure(self, tab: dict[str, Any]) -> None:
            self.start = float(tab["start_nm"])
            self.inv_step = 1.0 / float(tab["step_nm"])
            self.n_wl = len(tab["eta"])
            self.eta_tab = mi.Float(np.asarray(tab["eta"], np.float32))
            self.base_tab = mi.Float(np.asarray(tab["base"], np.float32))
            self.rough = tab["roughness"] is not None
            if self.rough:
                self.t_tab = mi.Float(np.asarray(tab["t"], np.float32).ravel())
                self.distr = mi.MicrofacetDistribution(
                    mi.MicrofacetType.Beckmann, float(tab["roughness"]), True
                )
            # Mitsuba's plastic: specular sampling weight 1 / (1 + mean diffuse albedo)
            self.spec_weight = 1.0 / (1.0 + float(tab["mean_albedo"]))
            lobe = mi.BSDFFlags.GlossyReflection if self.rough else mi.BSDFFlags.DeltaReflection
            diffuse = mi.BSDFFlags.DiffuseReflection | mi.BSDFFlags.FrontSide
            self.m_components = [lobe | mi.BSDFFlags.FrontSide, diffuse]
            self.m_flags = lobe | diffuse

        # ---- tables -------------------------------------------------------------------
        def _wl_index(self, lam: Any) -> tuple[Any, Any]:
            x = dr.clip((lam - self.start) * self.inv_step, 0.0, self.n_wl - 1.0001)
            i = mi.UInt32(x)
            return i, x - mi.Float(i)

        def _spectral(self, table: Any, lam: Any) -> Any:
            def one(wl: Any) -> Any:
                i, f = self._wl_index(wl)
                a = dr.gather(mi.Float, table, i)
                b = dr.gather(mi.Float, table, i + 1)
                return dr.fma(f, b - a, a)

            return per_wavelength(one, lam)

        def _transmittance(self, c: Any, eta: Any, lam: Any) -> Any:
            if not self.rough:
                return 1.0 - fresnel(c, eta)
            x = dr.clip(c, 0.0, 1.0) * (n_nodes - 1.0)
            j = mi.UInt32(dr.minimum(x, n_nodes - 1.0001))
            fc = x - mi.Float(j)

            def one(wl: Any) -> Any:
                i, f = self._wl_index(wl)
                r0, r1 = j * self.n_wl + i, (j + 1) * self.n_wl + i
                a0 = dr.gather(mi.Float, self.t_tab, r0)
                a1 = dr.gather(mi.Float, self.t_tab, r0 + 1)
                b0 = dr.gather(mi.Float, self.t_tab, r1)
                b1 = dr.gather(mi.Float, self.t_tab, r1 + 1)
                lo = dr.fma(f, a1 - a0, a0)
                hi = dr.fma(f, b1 - b0, b0)
                return dr.fma(fc, hi - lo, lo)

            return per_wavelength(one, lam)

        def _spec_prob(self, f_i: Any) -> Any:
            fm = mean(f_i)
            w = self.spec_weight
            return fm * w / dr.maximum(fm * w + (1.0 - fm) * (1.0 - w), 1e-12)

        # ---- the model ----------------------------------------------------------------
        def _eval_pdf(self, si: Any, wo: Any, active: Any) -> tuple[Any, Any]:
            cos_i, cos_o = mi.Frame3f.cos_theta(si.wi), mi.Frame3f.cos_theta(wo)
            active = active & (cos_i > 0.0) & (cos_o > 0.0)
            lam = si.wavelengths
            eta = self._spectral(self.eta_tab, lam)
            f_i = fresnel(cos_i, eta)
            p_s = self._spec_prob(f_i)
            t_i, t_o = self._transmittance(cos_i, eta, lam), self._transmittance(cos_o, eta, lam)
            value = self._spectral(self.base_tab, lam) * t_i * t_o * cos_o
            pdf = (1.0 - p_s) * dr.inv_pi * cos_o
            if self.rough:
                h = dr.normalize(si.wi + wo)
                d = self.distr.eval(h)
                g = self.distr.G(si.wi, wo, h)
                value += fresnel(dr.dot(si.wi, h), eta) * d * g / (4.0 * cos_i)
                pdf += p_s * self.distr.pdf(si.wi, h) / (4.0 * dr.abs(dr.dot(wo, h)))
            return dr.select(active, value, 0.0), dr.select(active, pdf, 0.0)

        def eval(self, ctx: Any, si: Any, wo: Any, active: Any = True) -> Any:
            return self._eval_pdf(si, wo, active)[0]

        def pdf(self, ctx: Any, si: Any, wo: Any, active: Any = True) -> Any:
            return self._eval_pdf(si, wo, active)[1]

        def eval_pdf(self, ctx: Any, si: Any, wo: Any, active: Any = True) -> Any:
            return self._eval_pdf(si, wo, active)

        def sample(self, ctx: Any, si: Any, sample1: Any, sample2: Any, active: Any = True) -> Any:
            cos_i = mi.Frame3f.cos_theta(si.wi)
            active = active & (cos_i > 0.0)
            eta = self._spectral(self.eta_tab, si.wavelengths)
            f_i = fresnel(cos_i, eta)
            p_s = self._spec_prob(f_i)
            chose_spec = sample1 < p_s
            bs = dr.zeros(mi.BSDFSample3f)
            bs.eta = 1.0
            diffuse_wo = mi.warp.square_to_cosine_hemisphere(sample2)
            if self.rough:
                m, _ = self.distr.sample(si.wi, sample2)
                spec_wo = mi.reflect(si.wi, m)
                bs.wo = dr.select(chose_spec, spec_wo, diffuse_wo)
                value, pdf = self._eval_pdf(si, bs.wo, active)
                bs.pdf = pdf
                bs.sampled_type = dr.select(
                    chose_spec,
                    mi.UInt32(+mi.BSDFFlags.GlossyReflection),
                    mi.UInt32(+mi.BSDFFlags.DiffuseReflection),
                )
                bs.sampled_component = dr.select(chose_spec, mi.UInt32(0), mi.UInt32(1))
                ok = active & (pdf > 0.0) & (mi.Frame3f.cos_theta(bs.wo) > 0.0)
                return bs, dr.select(ok, value / dr.maximum(pdf, 1e-30), 0.0)
            # smooth coat: a delta mirror lobe, or the diffuse base
            bs.wo = dr.select(chose_spec, mi.reflect(si.wi), diffuse_wo)
            cos_o = mi.Frame3f.cos_theta(diffuse_wo)
            bs.pdf = dr.select(chose_spec, p_s, (1.0 - p_s) * dr.inv_pi * cos_o)
            bs.sampled_type = dr.select(
                chose_spec,
                mi.UInt32(+mi.BSDFFlags.DeltaReflection),
                mi.UInt32(+mi.BSDFFlags.DiffuseReflection),
            )
            bs.sampled_component = dr.select(chose_spec, mi.UInt32(0), mi.UInt32(1))
            lam = si.wavelengths
            t_i = 1.0 - f_i
            t_o = self._transmittance(cos_o, eta, lam)
            diff_w = self._spectral(self.base_tab, lam) * t_i * t_o * dr.pi / (1.0 - p_s)
            weight = dr.select(chose_spec, f_i / dr.maximum(p_s, 1e-30), diff_w)
            ok = active & (bs.pdf > 0.0) & (mi.Frame3f.cos_theta(bs.wo) > 0.0)
            return bs, dr.select(ok, weight, 0.0)

        def traverse(self, callback: Any) -> None:
            return None

        def parameters_changed(self, keys: Any = None) -> None:
            return None

        def to_string(self) -> str:
            return f"CoatedDiffuse[rough={self.rough}, wavelengths={self.n_wl}]"

    return CoatedDiffuse
