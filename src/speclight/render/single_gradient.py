"""Single-scattering intensity and its derivatives in the roughness, from one ray cast.

In the single-scattering render (:mod:`speclight.render.single`) the ray cast, the shadow
test and every hit's cosines do not depend on a material's roughness alpha; only the
per-pixel weight of its main channel does, ``f cos_i / F = D G / (4 cos_o)``, whose spectral
factor (the Fresnel term at the half angle) does not. So

    dI/dalpha_k (lambda) = E(lambda) * R_k(lambda) * sum_pixels A_pix d(D G / (4 cos_o))/dalpha

over the pixels of material k, with the analytic derivative of
:func:`speclight.render.brdf_gradient.microfacet_weight_dalpha`. It is computed in the same
pass as the intensity: one extra channel per differentiated material, accumulated beside the
others (:class:`~speclight.render.material_channels.ChannelLayout`'s derivative channels,
summed in the single mode's kernel or its numpy path), so that it costs a fraction of
a render, not the two renders of a central difference.

Materials: those whose model gives the derivative
(:meth:`~speclight.render.bsdfs.MaterialBsdf.roughness_derivative`: ``beckmann``, ``ggx``).
``plastic`` is refused: the transmittance of its rough coat, which weights its diffuse base,
depends on alpha through a quadrature table
(:func:`~speclight.render.bsdfs.coat_optics.rough_coat_tables`) without a derivative here.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.render import material_channels as channels
from speclight.render.bsdfs import material_bsdf
from speclight.render.material_channels import ChannelLayout
from speclight.render.raycast import Caster
from speclight.render.single import channel_sum, geometric_weights
from speclight.target.materials import Material
from speclight.target.parts import Target

F64 = NDArray[np.float64]


def gradient_problem(m: Material) -> str:
    """Why the roughness derivative of material ``m`` is not available ("" when it is)."""
    return material_bsdf(m, "single").gradient_problem()


def render_single_gradient(
    target: Target,
    sun_dir: F64,
    obs_dir: F64,
    irradiance: F64,
    wavelength_nm: F64,
    caster: Caster,
    resolution_px: int,
    rough: list[str],
) -> tuple[F64, F64]:
    """Intensity (N, L) [W sr-1 nm-1] and its roughness derivatives (K, N, L) [W sr-1 nm-1].

    Parameters
    ----------
    target, sun_dir, obs_dir, irradiance, wavelength_nm, caster, resolution_px
        As :func:`speclight.render.single.render_single` (valid epochs only).
    rough
        Names of the K materials (``Material.name``) to differentiate by their roughness.

    Returns
    -------
    tuple
        The intensity, equal to :func:`~speclight.render.single.render_single`'s (the same
        sums in the same order), and ``d intensity / d alpha_k`` (module doc).
    """
    names = [m.name for m in target.materials]
    index = []
    for name in rough:
        if name not in names:
            raise InputError(
                f"no material '{name}' in the target (materials: {', '.join(names)})",
                field="target.materials",
            )
        k = names.index(name)
        problem = gradient_problem(target.materials[k])
        if problem:
            raise InputError(f"no roughness derivative: {problem}", field="target.materials")
        index.append(k)
    layout = ChannelLayout(target, index)
    w, _, _, _ = geometric_weights(
        target,
        sun_dir,
        obs_dir,
        caster,
        resolution_px,
        rays_per_batch=channels.rays_per_batch(target.materials),
        layout=layout,
    )
    total, main, _, _ = channel_sum(w, layout, sun_dir, obs_dir, wavelength_nm)
    intensity = irradiance * total
    grad = np.stack([irradiance * w[:, layout.grad[k], None] * main[k] for k in index])
    return np.asarray(intensity, dtype=float), grad.reshape(len(index), *intensity.shape)


__all__ = ["gradient_problem", "render_single_gradient"]
