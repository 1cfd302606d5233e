"""The previous path-mode plastic: Mitsuba's ``plastic`` / ``roughplastic`` set up to carry
the single-scattering mode's model (:mod:`.bsdf_plastic`).

Path mode now renders plastic coats with the spectral BSDF of :mod:`.path_coat` (the whole
spectrum in one render). This grouped model is kept for the scalar variants (no Dr.Jit
kernels to trace a Python BSDF into) and as the reference the tests compare the spectral
BSDF with (``render_path(..., coat='grouped')``).

Two differences are removed: Mitsuba's estimate of the coat's internal diffuse reflectance
F_dr,int (compensated through the base reflectance, exact for the linear model), and its single
real coat index (bins are rendered in groups, each with its own index). Mitsuba's rough-coat
transmittance table remains (up to 0.34 % off the single mode's at 70 deg, measured).
Reference: Jakob et al., Mitsuba 3 renderer, https://mitsuba-renderer.org (2022), plugins
``plastic`` and ``roughplastic`` (linear variant, ``nonlinear = false``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from speclight.render.bsdfs import coat_optics
from speclight.target.materials import Material
from speclight.target.parts import Target

F64 = NDArray[np.float64]
#: Largest spread of a plastic coat's index n within a group of bins (:func:`index_groups`).
COAT_INDEX_SPREAD = 0.004
MAX_INDEX_GROUPS = 32


def mitsuba_internal_reflectance(eta: float, roughness: float | None) -> float:
    """Mitsuba 3's own estimate of a coat's internal diffuse reflectance F_dr,int.

    Smooth ``plastic``: the fit of Egan & Hilgeman 1973 (Mitsuba's
    ``fresnel_diffuse_reflectance(1 / eta)``), 0.13 % off the exact integral at eta = 1.46.
    ``roughplastic``: ``2 * mean(R(mu_j; 1/eta) mu_j)`` over its 64 uniform cosine nodes,
    j / 63, which is 1.6-2 % below the integral 2 int R mu dmu (the mean divides by 64 nodes
    where a quadrature would weight 63 intervals). R is computed here independently
    (:func:`speclight.render.bsdfs.coat_optics.rough_coat_albedo`).
    """
    if roughness is None:
        e = 1.0 / eta
        return float(0.0636 / e + e * (e * -1.4399 + 0.7099) + 0.6681)
    mu = coat_optics.coat_table_nodes()
    r = coat_optics.rough_coat_albedo(mu, np.array([1.0 / eta]), float(roughness), transmit=False)
    return float(2.0 * np.mean(r[:, 0] * mu))


def group_bases(
    target: Target, groups: list[tuple[int, int, dict[int, float]]], grid: F64
) -> list[dict[int, F64]]:
    """Base reflectance handed to Mitsuba per group and plastic part, on ``grid`` [nm]."""
    out: list[dict[int, F64]] = [{} for _ in groups]
    for k in groups[0][2]:
        m = target.parts[k].material
        assert m.diffuse_reflectance is not None
        etas = np.array([g[2][k] for g in groups])
        exact = coat_optics.coat_transmittance(np.ones(1), etas, m.roughness)[1]
        nodes = np.linspace(etas.min(), etas.max(), max(2, int(np.ptp(etas) / 0.01) + 2))
        mits = np.interp(etas, nodes, [mitsuba_internal_reflectance(n, m.roughness) for n in nodes])
        rho = m.diffuse_reflectance.evaluate(grid)
        for j in range(len(groups)):
            out[j][k] = (1.0 - mits[j]) / (1.0 - exact[j]) * rho
    return out


def base_for_mitsuba(m: Material, eta: float, grid: F64) -> F64:
    """Base reflectance handed to Mitsuba for coat index ``eta`` (see :func:`group_bases`)."""
    assert m.diffuse_reflectance is not None
    exact = float(coat_optics.coat_transmittance(np.ones(1), np.array([eta]), m.roughness)[1][0])
    scale = (1.0 - mitsuba_internal_reflectance(eta, m.roughness)) / (1.0 - exact)
    return scale * m.diffuse_reflectance.evaluate(grid)


def index_groups(target: Target, wavelength_nm: F64) -> list[tuple[int, int, dict[int, float]]]:
    """Contiguous groups of wavelength bins rendered with one coat index per plastic part.

    Mitsuba's ``plastic`` / ``roughplastic`` take one real coat index; over the default grid
    n varies by 0.04 for SiO2 and 0.25 for Kapton (coat Fresnel reflectance up to 11 % and
    41 % off the mean-index value). Bins are grouped so that, for every plastic part, n
    spans at most :data:`COAT_INDEX_SPREAD` within a group, rendered at the group's mid-range
    index (|n - n_group| <= 0.002: the coat's Fresnel reflectance within 0.7 %, its diffuse
    base within 0.05 %); at most :data:`MAX_INDEX_GROUPS` groups (the spread doubles until
    they fit). Returns ``(first bin, end bin, {part index: n})`` per group.
    """
    wl = np.asarray(wavelength_nm, float)
    n_by_part = {
        k: p.material.reflectance.eta(wl).real
        for k, p in enumerate(target.parts)
        if p.material.bsdf == "plastic"
    }
    spread = COAT_INDEX_SPREAD
    while True:
        starts = [0]
        for j in range(1, len(wl)):
            a = starts[-1]
            if any(np.ptp(n[a : j + 1]) > spread for n in n_by_part.values()):
                starts.append(j)
        if len(starts) <= MAX_INDEX_GROUPS:
            break
        spread *= 2.0
    ends = [*starts[1:], len(wl)]
    return [
        (a, b, {k: float(0.5 * (n[a:b].min() + n[a:b].max())) for k, n in n_by_part.items()})
        for a, b in zip(starts, ends, strict=True)
    ]
