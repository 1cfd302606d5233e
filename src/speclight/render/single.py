"""Single-scattering render: one bounce of sunlight, with self-shadowing, evaluated exactly.

For each epoch an orthographic grid of rays (one per pixel centre) is cast along the line of
sight; each hit is tested for shadow by a ray towards the Sun, and the BRDF is evaluated for
the Sun and observer directions. Every model factorises into geometric weights times spectral
factors (see :mod:`speclight.render.bsdfs`), so one ray cast per epoch gives all
wavelengths, without noise in wavelength:

    I(lambda) = E(lambda) * sum_c w_c * R_c(lambda)      [W sr-1 nm-1]

with ``w_c = sum_pixels A_pix * f cos(theta_i) / R_c`` [m² sr-1] per channel c. The microfacet
Fresnel term depends on the half-angle, the same for all pixels of an epoch, so it is exact.
A smooth mirror (``specular``, smooth ``plastic`` coat) reflects the solar disk (uniform,
angular radius :data:`~speclight.illumination.SOLAR_ANGULAR_RADIUS_RAD`): a pixel whose mirror
direction falls inside the disk shows the radiance ``R * E / Omega_sun``. Surfaces are
two-sided (thin sheets reflect on both faces with the same material). RGL measured materials
(``.bsdf``) do not factorise: Mitsuba's ``measured`` plugin is evaluated per pixel at the
file's wavelength nodes, one channel per node (:mod:`speclight.render.rgl`).

Polarisation (:func:`render_single_polarized`): every polarising reflection of single
scattering (mirror, microfacet, plastic coat) has the half vector as its facet normal, so
its plane of incidence is the scattering plane of the epoch; the Stokes Q referenced to that
plane's normal is ``E sum_c w_c Q_c(lambda)`` with the same weights and the factors
``(R_s - R_p) / 2`` (:mod:`speclight.render.polarization`), and U = V = 0 in that frame.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from speclight.render import material_channels as channels
from speclight.render.camera import image_axes, primary_rays
from speclight.render.material_channels import ChannelLayout, pixel_contributions
from speclight.render.polarization import check_polarizable
from speclight.render.raycast import Caster
from speclight.render.result import RenderImage
from speclight.render.shading import dot_rows, half_vectors, mirror_in_sun
from speclight.target.parts import Target

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


@dataclass
class _Kept:
    """Pixel data of one kept epoch: contributions (pixel, channel, weight) and geometry."""

    pixel: I64
    channel: I64
    weight: F64
    part: I64
    depth_m: F64
    right: F64
    up: F64


def geometric_weights(
    target: Target,
    sun_dir: F64,
    obs_dir: F64,
    caster: Caster,
    resolution_px: int,
    keep: Iterable[int] = (),
    rays_per_batch: int = 1_000_000,
    on_batch: Callable[[int], None] | None = None,
    on_hits: Callable[..., None] | None = None,
    layout: ChannelLayout | None = None,
    contributions: Callable[..., tuple[I64, I64, F64]] = pixel_contributions,
) -> tuple[F64, dict[int, _Kept], float, ChannelLayout]:
    """Channel weights w (N, C) [m² sr-1], kept pixel data, pixel pitch [m] and the layout.

    ``on_hits(epochs, origin, direction, hits, caster)``, if given, is called after each
    batch's primary ray cast with the batch's epoch indices (so that other lights, e.g.
    lasers for ranging, reuse the rays: :mod:`speclight.render.laser_returns`).
    ``layout`` and ``contributions`` (same arguments as :func:`pixel_contributions`) add
    channels of their own, e.g. roughness derivatives (:mod:`speclight.render.single_gradient`).
    """
    layout = ChannelLayout(target) if layout is None else layout
    centre, radius = target.bounding_sphere()
    n_ep, n_ch = len(sun_dir), layout.n_channels
    pixels = resolution_px * resolution_px
    batch = max(1, rays_per_batch // pixels)
    keep_set = set(keep)
    w = np.zeros((n_ep, n_ch))
    kept: dict[int, _Kept] = {}
    pixel_area = (2.0 * radius / resolution_px) ** 2
    for a in range(0, n_ep, batch):
        s, o = sun_dir[a : a + batch], obs_dir[a : a + batch]
        b = len(s)
        origin, direction, pixel_area = primary_rays(centre, radius, o, resolution_px)
        hits = caster.intersect(origin, direction)
        if on_hits is not None:
            on_hits(np.arange(a, a + b), origin, direction, hits, caster)
        ep = np.repeat(np.arange(b), pixels)
        n = hits.normal
        cos_o = np.einsum("mk,mk->m", n, o[ep])
        flip = np.where(cos_o < 0, -1.0, 1.0)  # thin sheets reflect on both faces
        n = n * flip[:, None]
        cos_o = cos_o * flip
        cos_i = np.einsum("mk,mk->m", n, s[ep])
        idx = np.flatnonzero(hits.hit & (cos_i > 0) & (cos_o > 0))
        pos = origin[idx] + hits.t_m[idx, None] * direction[idx]
        idx = idx[~caster.occluded(pos, s[ep[idx]], n[idx])]
        e_idx = ep[idx]
        half = half_vectors(s, o)
        cos_h = dot_rows(n[idx], half[e_idx])
        cos_d = dot_rows(s, half)[e_idx]
        mirror_ok = mirror_in_sun(n[idx], cos_o[idx], o[e_idx], s[e_idx])
        mat = layout.part_mat[hits.part[idx]]
        rows, chans, px_w = contributions(
            layout, mat, cos_i[idx], cos_o[idx], cos_h, cos_d, mirror_ok
        )
        flat = e_idx[rows] * n_ch + chans
        w[a : a + b] = (np.bincount(flat, px_w, minlength=b * n_ch) * pixel_area).reshape(b, n_ch)
        for e in keep_set.intersection(range(a, a + b)):
            j = e - a
            sel = e_idx[rows] == j
            right, up = image_axes(o[j : j + 1])
            sl = slice(j * pixels, (j + 1) * pixels)
            kept[e] = _Kept(
                pixel=idx[rows[sel]] - j * pixels,
                channel=chans[sel],
                weight=px_w[sel] * pixel_area,
                part=hits.part[sl].copy(),
                depth_m=hits.t_m[sl] - 2.0 * radius,
                right=right[0],
                up=up[0],
            )
        if on_batch is not None:
            on_batch(b)
    return w, kept, float(np.sqrt(pixel_area)), layout


def render_single(
    target: Target,
    sun_dir: F64,
    obs_dir: F64,
    irradiance: F64,
    wavelength_nm: F64,
    caster: Caster,
    resolution_px: int,
    keep: Iterable[int] = (),
    on_batch: Callable[[int], None] | None = None,
    on_hits: Callable[..., None] | None = None,
) -> tuple[F64, dict[int, RenderImage]]:
    """Intensity (N, L) [W sr-1 nm-1] of valid epochs and the kept images (see module doc)."""
    intensity, _, images, _ = render_single_polarized(
        target, sun_dir, obs_dir, irradiance, wavelength_nm, caster, resolution_px, keep,
        on_batch, on_hits, polarization=False,
    )  # fmt: skip
    return intensity, images


def channel_sum(
    w: F64, layout: ChannelLayout, sun_dir: F64, obs_dir: F64, wavelength_nm: F64
) -> tuple[F64, list[F64], dict[int, F64], F64]:
    """``sum_c w_c R_c(lambda)`` (N, L) [m² sr-1] from the channel weights ``w`` (N, C).

    Also returns the main channels' spectral factors (per material, (N, L)), the block
    factors (per plastic material, (nodes, L)) and the cosine of the half-phase angle (N,).
    """
    cos_half = np.sqrt(np.clip(0.5 * (1.0 + np.einsum("nk,nk->n", sun_dir, obs_dir)), 0.0, 1.0))
    n_mat = len(layout.mats)
    main = [bsdf.main_factor(cos_half, wavelength_nm) for bsdf in layout.bsdfs]
    blocks = {k: layout.bsdfs[k].block_factor(wavelength_nm) for k in layout.block}
    total = sum(w[:, k, None] * main[k] for k in range(n_mat))
    for k, start in layout.block.items():
        total = total + w[:, start : start + blocks[k].shape[0]] @ blocks[k]
    return np.asarray(total, dtype=float), main, blocks, cos_half


def outside_support_sum(w: F64, layout: ChannelLayout, blocks: dict[int, F64]) -> F64 | None:
    """``sum_c w_c R_c(lambda)`` (N, L) [m² sr-1] over the channels of light from outside a
    measured table's support (:attr:`ChannelLayout.outside`); None when the target has none."""
    if not layout.outside.any():
        return None
    total = np.zeros((w.shape[0], next(iter(blocks.values())).shape[1]))
    for k, start in layout.block.items():
        size = blocks[k].shape[0]
        mask = layout.outside[start : start + size]
        if mask.any():
            total += w[:, start : start + size][:, mask] @ blocks[k][mask]
    return total


def render_single_polarized(
    target: Target,
    sun_dir: F64,
    obs_dir: F64,
    irradiance: F64,
    wavelength_nm: F64,
    caster: Caster,
    resolution_px: int,
    keep: Iterable[int] = (),
    on_batch: Callable[[int], None] | None = None,
    on_hits: Callable[..., None] | None = None,
    polarization: bool = True,
) -> tuple[F64, F64 | None, dict[int, RenderImage], F64 | None]:
    """Intensity (N, L), its linear polarisation Q_s (N, L) [W sr-1 nm-1], kept images, and
    the part of the intensity from outside measured tables' support (N, L) [W sr-1 nm-1]
    (None: no material has a support; :mod:`speclight.target.brdf_table`).

    ``Q_s`` is the Stokes Q referenced to the normal of the scattering plane (the plane of
    the Sun and observer directions): positive when the light is polarised perpendicular to
    it. U = V = 0 in that frame: every polarising reflection of single scattering (mirror,
    microfacet, plastic coat) has its plane of incidence in the scattering plane
    (:mod:`speclight.render.polarization`); diffuse channels are unpolarised. Without
    ``polarization``: :func:`render_single`, and ``Q_s`` is None. With it, each kept image's
    ``stokes_qu_W_m2_sr_nm`` holds the per-pixel (Q_s, 0) in the same frame.
    """
    if polarization:
        check_polarizable(target.materials)
    keep = list(keep)
    w, kept, pitch, layout = geometric_weights(
        target,
        sun_dir,
        obs_dir,
        caster,
        resolution_px,
        keep,
        rays_per_batch=channels.rays_per_batch(target.materials),
        on_batch=on_batch,
        on_hits=on_hits,
    )
    total, main, blocks, cos_half = channel_sum(w, layout, sun_dir, obs_dir, wavelength_nm)
    n_mat = len(layout.mats)
    intensity = irradiance * total
    outside = outside_support_sum(w, layout, blocks)
    if outside is not None:
        outside *= irradiance
    linear = None
    if polarization:  # the block channels (diffuse bases) are unpolarised
        q = [bsdf.linear_factor(cos_half, wavelength_nm) for bsdf in layout.bsdfs]
        linear = irradiance * sum(w[:, k, None] * q[k] for k in range(n_mat))
    images: dict[int, RenderImage] = {}
    for e, kp in kept.items():
        factor = np.zeros((layout.n_channels, len(wavelength_nm)))
        for k in range(n_mat):
            factor[k] = main[k][e]
        for k, start in layout.block.items():
            factor[start : start + blocks[k].shape[0]] = blocks[k]
        pixels = resolution_px * resolution_px
        spec = np.zeros((pixels, len(wavelength_nm)))
        np.add.at(spec, kp.pixel, kp.weight[:, None] * factor[kp.channel])
        qu = None
        if polarization:  # Q_s per pixel, as for the total; U = 0 in this frame
            lin = np.zeros((layout.n_channels, len(wavelength_nm)))
            for k in range(n_mat):
                lin[k] = q[k][e]
            q_px = np.zeros((pixels, len(wavelength_nm)))
            np.add.at(q_px, kp.pixel, kp.weight[:, None] * lin[kp.channel])
            qu = np.stack([q_px, np.zeros_like(q_px)], axis=-1) * irradiance[e][:, None] / pitch**2
            qu = qu.reshape(resolution_px, resolution_px, len(wavelength_nm), 2)
        images[e] = RenderImage(
            epoch=e,
            radiance_W_m2_sr_nm=(spec * irradiance[e] / pitch**2).reshape(
                resolution_px, resolution_px, -1
            ),
            depth_m=kp.depth_m.reshape(resolution_px, resolution_px),
            part_index=kp.part.reshape(resolution_px, resolution_px),
            pixel_size_m=pitch,
            right_body=kp.right,
            up_body=kp.up,
            stokes_qu_W_m2_sr_nm=qu,
        )
    return intensity, linear, images, outside


def material_contributions(
    target: Target,
    sun_dir: F64,
    obs_dir: F64,
    irradiance: F64,
    wavelength_nm: F64,
    caster: Caster,
    resolution_px: int,
) -> F64:
    """Each material's share of the intensity (N, M, L) [W sr-1 nm-1] (see module doc).

    Entry ``[:, k, :]`` is ``E(lambda) * (w_k R_k(lambda) + the block channels of k)`` over
    the pixels that see material k (``target.materials`` order); the sum over k is the
    intensity of :func:`render_single` (to rounding).
    """
    w, _, _, layout = geometric_weights(
        target,
        sun_dir,
        obs_dir,
        caster,
        resolution_px,
        rays_per_batch=channels.rays_per_batch(target.materials),
    )
    cos_half = np.sqrt(np.clip(0.5 * (1.0 + np.einsum("nk,nk->n", sun_dir, obs_dir)), 0.0, 1.0))
    out = np.zeros((len(sun_dir), len(layout.mats), len(wavelength_nm)))
    for k, bsdf in enumerate(layout.bsdfs):
        out[:, k] = w[:, k, None] * bsdf.main_factor(cos_half, wavelength_nm)
        if k in layout.block:
            block = bsdf.block_factor(wavelength_nm)
            start = layout.block[k]
            out[:, k] += w[:, start : start + block.shape[0]] @ block
    return out * irradiance[:, None, :]
