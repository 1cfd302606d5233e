"""Per-material pieces of the single-scattering render: pixel weights and spectral factors.

Each material contributes through *channels*: a geometric weight per pixel [sr-1] (summed over
pixels times the pixel area) and a spectral factor [1]. The main channel of every material has
a factor that depends only on the epoch (through the half-phase angle); a ``plastic`` material
adds ``PLASTIC_NODES**2`` channels for its diffuse base, binned bilinearly in
(cos theta_i, cos theta_o) with epoch-independent factors.

Plastic (a diffuse base under a transparent dielectric coat of real index n(lambda), the
coat's k ignored): coat reflection F(theta; n) (smooth: a mirror; rough: the Beckmann
microfacet lobe) plus the diffuse base, Mitsuba 3's linear ``plastic`` / ``roughplastic``
model f_d = rho_d T(theta_i) T(theta_o) / (n^2 pi (1 - F_dr,int)) (Weidlich & Wilkie 2007,
"Arbitrarily layered micro-facet surfaces", doi:10.1145/1321261.1321292). Smooth coat:
T = 1 - F. Rough coat: T is the energy the rough interface refracts, the microfacet
transmission integral with Smith masking (Walter et al. 2007, doi:10.2312/EGWR/EGSR07/195-206;
Heitz 2014, JCGT 3(2)), which also loses the energy of the shadowed reflection; F_dr,int is
2 int R(mu; 1/n) mu dmu with R the smooth (Fresnel) or rough (microfacet) internal
reflectance, computed by quadrature (:func:`rough_coat_tables`). ``rho_d`` is the effective
albedo of the coated base (linear model): a measured diffuse reflectance can be used as is.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from speclight.cache import cached_arrays
from speclight.errors import InputError
from speclight.illumination.solar import SOLAR_ANGULAR_RADIUS_RAD
from speclight.render import rgl
from speclight.render.brdf import microfacet_weight
from speclight.render.rgl import is_rgl
from speclight.target.brdf_table import load_brdf_table
from speclight.target.materials import Material
from speclight.target.optical_constants import fresnel_reflectance
from speclight.target.parts import Target

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


def sun_disk_sin2() -> float:
    """sin^2 of the angular radius of the path mode's solar disk: the solar disk
    (:data:`~speclight.illumination.SOLAR_ANGULAR_RADIUS_RAD`), rounded so that
    ``1 - cos(theta)`` is a whole number of float32 steps (2^-24).

    Mitsuba samples a sphere emitter by its cone with the density
    ``1 / (2 pi (1 - cos theta_max))``, ``cos theta_max`` computed in float32 from sin^2:
    for the Sun (1 - cos = 1.08e-5, 181 float32 steps) an arbitrary radius is off by up to
    half a step, a bias of up to 0.3 % in every sunlit pixel. With 1 - cos an exact number
    of steps the float32 value is exact; the disk's solid angle is 0.23 % below the Sun's
    (radius 0.2661 instead of 0.2665 deg; the Sun's own varies by 3.4 % over a year), so the
    radiance of a mirror glint is 0.23 % above the single mode's (which uses
    :data:`SUN_SOLID_ANGLE_SR`); irradiance and glint power are unchanged.
    """
    step = 2.0**-24
    delta = round((1.0 - np.cos(SOLAR_ANGULAR_RADIUS_RAD)) / step) * step
    return float(2.0 * delta - delta * delta)


SUN_COS = float(np.cos(SOLAR_ANGULAR_RADIUS_RAD))
SUN_SOLID_ANGLE_SR = float(2.0 * np.pi * (1.0 - SUN_COS))

PLASTIC_NODES = 33
#: Largest coat-index step of the rough-coat tables' index grid (interpolated between).
COAT_ETA_STEP = 0.01
SUPPORTED = ("lambertian", "beckmann", "ggx", "specular", "plastic", "measured")


def check_supported(materials: tuple[Material, ...] | list[Material]) -> None:
    """Raise an InputError naming the first material whose ``bsdf`` no render model has."""
    for m in materials:
        if m.bsdf not in SUPPORTED:
            raise InputError(
                f"material '{m.name}': bsdf '{m.bsdf}' is not known "
                f"(accepted: {', '.join(SUPPORTED)})",
                field=f"target.materials.{m.name}.bsdf",
            )


def main_weight(m: Material, cos_i: F64, cos_o: F64, cos_h: F64, cos_d: F64, mirror_ok: F64) -> F64:
    """Per-pixel weight [sr-1] of a material's main channel (f cos_i over its factor)."""
    if m.bsdf == "lambertian":
        return cos_i / np.pi
    if m.bsdf in ("beckmann", "ggx"):
        return microfacet_weight(cos_i, cos_o, cos_h, float(m.roughness or 0.0), m.bsdf)
    if m.bsdf == "specular" or (m.bsdf == "plastic" and m.roughness is None):
        return mirror_ok / SUN_SOLID_ANGLE_SR
    if m.bsdf == "plastic":
        return microfacet_weight(cos_i, cos_o, cos_h, float(m.roughness or 0.0), "beckmann")
    if is_rgl(m):  # non-factorising: all its light goes through its block channels
        return np.zeros_like(cos_i)
    if m.bsdf == "measured":
        table = load_brdf_table(str(m.brdf_table))
        th = np.degrees(np.arccos(np.clip(cos_h, -1.0, 1.0)))
        td = np.degrees(np.arccos(np.clip(cos_d, -1.0, 1.0)))
        return table(th, td) * cos_i
    check_supported([m])  # raises the InputError naming the material and the accepted names
    raise AssertionError(f"bsdf '{m.bsdf}' is in SUPPORTED but has no pixel weight")


def main_factor(m: Material, cos_half_phase: F64, wavelength_nm: F64) -> F64:
    """Spectral factor (N, L) of a material's main channel for epochs' half-phase cosines."""
    refl = m.reflectance
    n = len(cos_half_phase)
    if is_rgl(m):
        return np.zeros((n, len(wavelength_nm)))
    if m.bsdf == "measured":
        table = load_brdf_table(str(m.brdf_table))
        ref = refl.evaluate(np.array([table.wavelength_nm]))[0] if refl.kind != "constant" else 1.0
        ratio = (
            refl.evaluate(wavelength_nm) / ref
            if refl.kind != "constant"
            else np.ones(len(wavelength_nm))
        )
        return np.broadcast_to(ratio[None, :], (n, len(wavelength_nm)))
    if m.bsdf == "lambertian" or not refl.is_fresnel:
        return np.broadcast_to(refl.evaluate(wavelength_nm)[None, :], (n, len(wavelength_nm)))
    c = np.where(np.isfinite(cos_half_phase), cos_half_phase, 1.0)
    if m.bsdf == "plastic":  # a transparent coat: its real index n only, as for the base
        eta = refl.eta(wavelength_nm).real
        return fresnel_reflectance(c[:, None], eta[None, :])
    return refl.at_incidence(c, wavelength_nm)


def internal_diffuse_reflectance(eta: F64, n_mu: int = 4000) -> F64:
    """F_dr,int = 2 int_0^1 F(mu; 1/eta) mu dmu: hemispherical reflectance seen from inside."""
    mu = (np.arange(n_mu) + 0.5) / n_mu
    f = fresnel_reflectance(mu[:, None], (1.0 / np.asarray(eta))[None, :])
    return 2.0 * np.sum(f * mu[:, None], axis=0) / n_mu


def plastic_nodes() -> F64:
    """Cosine nodes of the plastic diffuse binning grid."""
    return np.linspace(0.0, 1.0, PLASTIC_NODES)


def plastic_factor(m: Material, wavelength_nm: F64) -> F64:
    """Spectral factors (K*K, L) of a plastic's diffuse channels at the (cos_i, cos_o) nodes.

    Given an RGL material, the factors of its block instead (see :func:`block_factor`).
    """
    if is_rgl(m):
        return block_factor(m, wavelength_nm)
    assert m.diffuse_reflectance is not None
    eta = m.reflectance.eta(wavelength_nm).real
    t, f_dr = coat_transmittance(plastic_nodes(), eta, m.roughness)  # (K, L), (L,)
    rho = m.diffuse_reflectance.evaluate(wavelength_nm)
    scale = rho / (eta**2 * (1.0 - f_dr))
    return (t[:, None, :] * t[None, :, :] * scale).reshape(-1, len(wavelength_nm))


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


def bilinear_nodes(cos_i: F64, cos_o: F64) -> tuple[NDArray[np.int64], F64]:
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


def block_size(m: Material) -> int:
    """Number of extra (block) channels of a material: 0 unless plastic or RGL measured.

    Blocks hold what does not factorise into one weight times one spectral factor: the
    plastic's diffuse base binned in (cos_i, cos_o), and an RGL material's BRDF at its file's
    wavelength nodes (:mod:`speclight.render.rgl`); each block channel has an
    epoch-independent spectral factor (:func:`block_factor`).
    """
    if m.bsdf == "plastic":
        return PLASTIC_NODES**2
    if is_rgl(m):
        return rgl.node_count(m)
    return 0


def block_weights(
    m: Material, cos_i: F64, cos_o: F64, cos_d: F64
) -> tuple[NDArray[np.int64], NDArray[np.int64], F64]:
    """(row into the inputs, channel within the block, weight [sr-1]) of a material's block."""
    if m.bsdf == "plastic":
        idx, bw = bilinear_nodes(cos_i, cos_o)
        rows = np.repeat(np.arange(len(cos_i)), 4)
        return rows, idx.ravel(), (bw * (cos_i / np.pi)[:, None]).ravel()
    if is_rgl(m):
        w = rgl.pixel_weights(m, cos_i, cos_o, cos_d)  # (P, W)
        rows = np.repeat(np.arange(len(cos_i)), w.shape[1])
        return rows, np.tile(np.arange(w.shape[1]), len(cos_i)), w.ravel()
    empty = np.zeros(0, np.int64)
    return empty, empty, np.zeros(0)


def block_factor(m: Material, wavelength_nm: F64) -> F64:
    """Spectral factors (block_size, L) of a material's block channels [1]."""
    if is_rgl(m):
        return rgl.hat_factor(m, wavelength_nm)
    return plastic_factor(m, wavelength_nm)


#: Primary rays per single-mode batch without RGL materials.
RAYS_PER_BATCH = 1_000_000
#: Pixel contributions (pixel, channel, weight) held at once in a single-mode batch with RGL
#: materials (about 40 bytes each).
CONTRIBUTIONS_PER_BATCH = 4_000_000


def rays_per_batch(materials: tuple[Material, ...] | list[Material]) -> int:
    """Primary rays per single-mode batch: :data:`RAYS_PER_BATCH`, fewer with RGL materials
    (one contribution per pixel and wavelength node of the file) so that a batch holds about
    :data:`CONTRIBUTIONS_PER_BATCH`; at least one epoch is always cast at once."""
    nodes = max((rgl.node_count(m) for m in materials if is_rgl(m)), default=0)
    return min(RAYS_PER_BATCH, CONTRIBUTIONS_PER_BATCH // (1 + nodes))


#: Cosine nodes of the rough-coat transmittance table (uniform in [0, 1], first at 1e-6),
#: linearly interpolated between nodes, as in Mitsuba 3's ``roughplastic``.
COAT_TABLE_NODES = 64
#: Gauss-Legendre nodes per axis of the microfacet-normal quadrature (outside / inside: the
#: inside integrand has the total-internal-reflection edge, hence more nodes).
_QUAD_OUT, _QUAD_IN = 48, 160


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
    Smith term of :func:`speclight.render.brdf.smith_g1`; ``eta`` < 1 seen from inside.
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


class ChannelLayout:
    """Channel layout: main channel m for material m, then a block per plastic or RGL material.

    Blocks (:func:`speclight.render.material_block_size`) carry what does not
    factorise: K*K channels of a plastic's diffuse base, one channel per wavelength node of an
    RGL file.
    """

    def __init__(self, target: Target) -> None:
        self.mats = list(target.materials)
        self.part_mat = target.part_material_index
        self.block: dict[int, int] = {}
        c = len(self.mats)
        for k, m in enumerate(self.mats):
            extra = block_size(m)  # plastic base, RGL wavelength nodes
            if extra:
                self.block[k] = c
                c += extra
        self.n_channels = c


def pixel_contributions(
    layout: ChannelLayout, mat: I64, cos_i: F64, cos_o: F64, cos_h: F64, cos_d: F64, mirror_ok: F64
) -> tuple[I64, I64, F64]:
    """(pixel position in the input, channel, weight [sr-1]) of every contribution.

    ``mat`` (M,) is each pixel's material index; the cosines are those of
    :mod:`speclight.render.shading`; ``mirror_ok`` (M,) is 1 where a smooth mirror glints.
    """
    rows, chans, weights = [], [], []
    for k, m in enumerate(layout.mats):
        sel = np.flatnonzero(mat == k)
        if sel.size == 0:
            continue
        w = main_weight(m, cos_i[sel], cos_o[sel], cos_h[sel], cos_d[sel], mirror_ok[sel])
        rows.append(sel)
        chans.append(np.full(sel.size, k))
        weights.append(w)
        if k in layout.block:
            r, c, bw = block_weights(m, cos_i[sel], cos_o[sel], cos_d[sel])
            rows.append(sel[r])
            chans.append(layout.block[k] + c)
            weights.append(bw)
    if not rows:
        return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0)
    return np.concatenate(rows), np.concatenate(chans), np.concatenate(weights)
