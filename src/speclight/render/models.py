"""Per-material pieces of the single-scattering render: pixel weights and spectral factors.

Each material contributes through *channels*: a geometric weight per pixel [sr-1] (summed over
pixels times the pixel area) and a spectral factor [1]. The main channel of every material has
a factor that depends only on the epoch (through the half-phase angle); a ``plastic`` material
adds ``PLASTIC_NODES**2`` channels for its diffuse base, binned bilinearly in
(cos theta_i, cos theta_o) with epoch-independent factors.

Plastic follows Mitsuba 3's ``plastic`` BSDF (linear variant): specular coat reflection
F(theta) plus a diffuse base
f_d = rho_d (1 - F(theta_i)) (1 - F(theta_o)) / (eta^2 pi (1 - F_dr,int)), with F_dr,int the
coat's internal diffuse reflectance (Weidlich & Wilkie 2007, "Arbitrarily layered
micro-facet surfaces", doi:10.1145/1321261.1321292; Jakob et al., Mitsuba 3 documentation).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from speclight.illumination.solar import SOLAR_ANGULAR_RADIUS_RAD
from speclight.render import rgl
from speclight.render.brdf import microfacet_weight
from speclight.render.rgl import is_rgl
from speclight.target.brdf_table import load_brdf_table
from speclight.target.materials import Material
from speclight.target.optical_constants import fresnel_reflectance

F64 = NDArray[np.float64]
SUN_COS = float(np.cos(SOLAR_ANGULAR_RADIUS_RAD))
SUN_SOLID_ANGLE_SR = float(2.0 * np.pi * (1.0 - SUN_COS))
PLASTIC_NODES = 33
SUPPORTED = ("lambertian", "beckmann", "ggx", "specular", "plastic", "measured")


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
    raise NotImplementedError(f"bsdf '{m.bsdf}' is not supported (supported: {SUPPORTED})")


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
    c = plastic_nodes()
    t = 1.0 - fresnel_reflectance(c[:, None], eta[None, :])  # (K, L) transmittance of the coat
    rho = m.diffuse_reflectance.evaluate(wavelength_nm)
    scale = rho / (eta**2 * (1.0 - internal_diffuse_reflectance(eta)))
    return (t[:, None, :] * t[None, :, :] * scale).reshape(-1, len(wavelength_nm))


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
