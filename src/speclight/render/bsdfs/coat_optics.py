"""Optics of a plastic's dielectric coat: transmittance and internal diffuse reflectance.

Plastic (a diffuse base under a transparent dielectric coat of real index n(lambda), the
coat's k ignored) follows Mitsuba 3's linear ``plastic`` / ``roughplastic`` model
f_d = rho_d T(theta_i) T(theta_o) / (n^2 pi (1 - F_dr,int)) (Weidlich & Wilkie 2007,
"Arbitrarily layered micro-facet surfaces", doi:10.1145/1321261.1321292). Smooth coat:
T = 1 - F. Rough coat: T is the energy the rough interface refracts, the microfacet
transmission integral with Smith masking (Walter et al. 2007, doi:10.2312/EGWR/EGSR07/195-206;
Heitz 2014, JCGT 3(2)), which also loses the energy of the shadowed reflection; F_dr,int is
2 int R(mu; 1/n) mu dmu with R the smooth (Fresnel) or rough (microfacet) internal
reflectance, computed by quadrature (:func:`rough_coat_tables`). The single mode
(:mod:`.bsdf_plastic`) and path mode (:mod:`.path_coat`, :mod:`.path_plastic`) share them.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from speclight.cache import cached_arrays
from speclight.target.optical_constants import fresnel_reflectance

F64 = NDArray[np.float64]

#: Largest coat-index step of the rough-coat tables' index grid (interpolated between).
COAT_ETA_STEP = 0.01
#: Cosine nodes of the rough-coat transmittance table (uniform in [0, 1], first at 1e-6),
#: linearly interpolated between nodes, as in Mitsuba 3's ``roughplastic``.
COAT_TABLE_NODES = 64
#: Gauss-Legendre nodes per axis of the microfacet-normal quadrature (outside / inside: the
#: inside integrand has the total-internal-reflection edge, hence more nodes).
_QUAD_OUT, _QUAD_IN = 48, 160


def internal_diffuse_reflectance(eta: F64, n_mu: int = 4000) -> F64:
    """F_dr,int = 2 int_0^1 F(mu; 1/eta) mu dmu: hemispherical reflectance seen from inside."""
    mu = (np.arange(n_mu) + 0.5) / n_mu
    f = fresnel_reflectance(mu[:, None], (1.0 / np.asarray(eta))[None, :])
    return 2.0 * np.sum(f * mu[:, None], axis=0) / n_mu


def coat_transmittance(cos_theta: F64, eta: F64, roughness: float | None) -> tuple[F64, F64]:
    """Coat transmittance (K, L) at ``cos_theta`` and internal diffuse reflectance (L,).

    Smooth coat: ``1 - F(theta; eta)`` and F_dr,int of :func:`internal_diffuse_reflectance`.
    Rough coat (Beckmann alpha): :func:`rough_coat_tables`, computed on a grid of indices
    spaced by at most :data:`COAT_ETA_STEP` and interpolated linearly in the index (the
    tabulated quantities are smooth in eta: the interpolation error is below 1e-5); the
    transmittance is interpolated linearly between its cosine nodes, as in Mitsuba 3.
    """
    eta = np.asarray(eta, float)
    c = np.asarray(cos_theta, float)
    if roughness is None:
        return 1.0 - fresnel_reflectance(c[:, None], eta[None, :]), internal_diffuse_reflectance(
            eta
        )
    lo, hi = float(eta.min()), float(eta.max())
    n = max(2, int(np.ceil((hi - lo) / COAT_ETA_STEP)) + 1)
    grid = np.linspace(lo, hi, n) if hi > lo else np.array([lo])
    table, f_grid = _rough_tables_cached(tuple(np.round(grid, 10)), float(roughness))
    if len(grid) == 1:
        t_nodes, f_dr = np.repeat(table, len(eta), axis=1), np.full(len(eta), f_grid[0])
    else:
        t_nodes = np.stack([np.interp(eta, grid, row) for row in table])
        f_dr = np.interp(eta, grid, f_grid)
    nodes = coat_table_nodes()
    t = np.stack([np.interp(c, nodes, t_nodes[:, j]) for j in range(len(eta))], axis=1)
    return t, f_dr


@lru_cache(maxsize=32)
def _rough_tables_cached(eta: tuple[float, ...], alpha: float) -> tuple[F64, F64]:
    """:func:`rough_coat_tables`, kept in memory and in the on-disk cache (seconds to make)."""
    key = {
        "eta": list(eta),
        "alpha": alpha,
        "nodes": COAT_TABLE_NODES,
        "quadrature": [_QUAD_OUT, _QUAD_IN, 96],
        "version": 1,
    }

    def compute() -> dict[str, F64]:
        t, f_dr = rough_coat_tables(np.array(eta), alpha)
        return {"t": t, "f_dr": f_dr}

    arrays = cached_arrays("rough-coat", key, compute)
    return arrays["t"], arrays["f_dr"]


def _beckmann_g1(cos_v: F64, sin_v: F64, v_dot_m: F64, alpha: float) -> F64:
    """Smith G1 of a direction (Walter et al. 2007 rational fit, as Mitsuba 3) with the
    orientation rule: zero when the direction sees the back of the microfacet."""
    tan = sin_v / np.maximum(np.abs(cos_v), 1e-30)
    a = 1.0 / np.maximum(alpha * tan, 1e-30)
    g = np.where(a >= 1.6, 1.0, (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a))
    return np.where(v_dot_m * cos_v > 0, g, 0.0)


def _fresnel_real(c: F64, eta: F64) -> F64:
    """Unpolarised Fresnel reflectance for a real relative index (1 beyond the critical
    angle); Hecht, Optics, eqs. 4.42-4.43."""
    s2 = (1.0 - c * c) / (eta * eta)
    ct = np.sqrt(np.maximum(1.0 - s2, 0.0))
    rs = (c - eta * ct) / np.maximum(c + eta * ct, 1e-300)
    rp = (eta * c - ct) / np.maximum(eta * c + ct, 1e-300)
    return np.where(s2 >= 1.0, 1.0, 0.5 * (rs * rs + rp * rp))


def rough_coat_albedo(mu: F64, eta: F64, alpha: float, *, transmit: bool) -> F64:
    """Directional reflectance or transmittance (M, E) of a Beckmann-rough dielectric interface.

    ``R(mu) = int D_wi(m) G1(wo, m) F(wi.m) dm`` (reflection) or
    ``T(mu) = int D_wi(m) G1(wt, m) (1 - F(wi.m)) dm`` (refraction into the coat), with the
    distribution of visible normals ``D_wi(m) = G1(wi, m) <wi.m> D(m) / mu`` (Heitz 2014,
    "Understanding the masking-shadowing function", JCGT 3(2), eqs. 38-39) and the separable
    Smith term of :func:`speclight.target.microfacet_terms.smith_g1`; ``eta`` < 1 seen from inside.
    Integrated over Beckmann microfacet normals with Gauss-Legendre nodes in the normal's
    cumulative distribution (tan^2 theta_m = -alpha^2 ln(1 - u)) and azimuth.
    """
    mu = np.asarray(mu, float)[:, None, None, None]
    eta = np.asarray(eta, float)[None, :, None, None]
    k = _QUAD_OUT if np.all(eta > 1) else _QUAD_IN
    x, w = np.polynomial.legendre.leggauss(k)
    u, wu = 0.5 * (x + 1), 0.5 * w
    phi = np.pi * (x + 1)  # azimuth in [0, 2 pi]; weights 0.5 w each (mean over the circle)
    tan2 = -(alpha**2) * np.log1p(-u)
    cm = (1.0 / np.sqrt(1.0 + tan2))[None, None, :, None]
    sm = np.sqrt(1.0 - cm**2)
    mx, my = sm * np.cos(phi)[None, None, None, :], sm * np.sin(phi)[None, None, None, :]
    si = np.sqrt(np.maximum(1.0 - mu**2, 0.0))
    d = si * mx + mu * cm  # wi . m
    vis = _beckmann_g1(mu, si, d, alpha) * np.maximum(d, 0.0) / (mu * cm)
    f = _fresnel_real(np.clip(d, 0.0, 1.0), eta)
    if transmit:  # refracted direction wt = -eta_ti wi + (eta_ti d - cos_t) m, eta_ti = 1/eta
        ct2 = 1.0 - (1.0 - d * d) / eta**2
        ct = np.sqrt(np.maximum(ct2, 0.0))
        r = 1.0 / eta
        ox, oy, oz = (-r * si + (r * d - ct) * mx, (r * d - ct) * my, -r * mu + (r * d - ct) * cm)
        h = np.where((ct2 > 0) & (oz < 0), 1.0 - f, 0.0)
    else:  # mirror direction wo = 2 d m - wi
        ox, oy, oz = 2 * d * mx - si, 2 * d * my, 2 * d * cm - mu
        h = np.where(oz > 0, f, 0.0)
    so = np.sqrt(np.maximum(ox**2 + oy**2, 0.0))
    g_o = _beckmann_g1(oz, so, ox * mx + oy * my + oz * cm, alpha)
    return np.einsum("meij,i,j->me", vis * g_o * h, wu, 0.5 * w)


def _per_eta(mu: F64, eta: F64, alpha: float, transmit: bool) -> F64:
    """:func:`rough_coat_albedo` one index at a time (bounded memory)."""
    cols = [rough_coat_albedo(mu, np.array([e]), alpha, transmit=transmit) for e in eta]
    return np.concatenate(cols, axis=1)


def rough_coat_tables(eta: F64, alpha: float) -> tuple[F64, F64]:
    """Coat transmittance table T (COAT_TABLE_NODES, E) at :func:`coat_table_nodes` and the
    internal diffuse reflectance F_dr,int (E,) = 2 int R(mu; 1/eta) mu dmu of a rough coat."""
    mu = coat_table_nodes()
    t = _per_eta(mu, np.asarray(eta, float), alpha, True)
    x, w = np.polynomial.legendre.leggauss(96)
    m2 = 0.5 * (x + 1)
    r_in = _per_eta(m2, 1.0 / np.asarray(eta, float), alpha, False)
    return t, np.einsum("me,m->e", r_in, w * m2)


def coat_table_nodes() -> F64:
    """Cosine nodes of the rough-coat transmittance table."""
    return np.maximum(1e-6, np.linspace(0.0, 1.0, COAT_TABLE_NODES))
