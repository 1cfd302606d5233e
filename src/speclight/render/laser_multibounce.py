"""Multi-bounce laser returns at their full optical path length (``render.mode: path``).

Mitsuba's integrators return radiance, not the distribution of path lengths (its core has no
transient/time-gated rendering), so the interreflections are traced here: a Monte Carlo path
tracer in numpy over the same ray caster (Mitsuba's ``ray_intersect``/``ray_test`` or the
numpy one), started from the receiver's primary hits of :mod:`speclight.render.laser_returns`.

Estimator (Kajiya 1986, "The rendering equation", doi:10.1145/15886.15902; Veach 1997, PhD
thesis, Stanford, ch. 3 and 16). From the first hit ``p1`` (seen along ``o``), a direction
``w`` is drawn from the cosine-weighted hemisphere about the normal (pdf cos/pi), giving the
next vertex ``p2`` where the ray hits; the path throughput is multiplied by
``f(w, v) cos / pdf = pi f(w, v)`` (spectral, on the laser's support wavelengths); at each
vertex ``p_j`` (``j >= 2``) the laser is sampled directly (next-event estimation: a shadow
ray towards the directional laser) and contributes ``throughput x f(l, v_j) cos_l x E``,
times the pixel area, at the one-way range offset

    delta = (-(p1 - c) . o + sum_i |p_{i+1} - p_i| - (p_j - c) . l) / 2

(receiver plane and transmitter plane through the centre of mass ``c``). The one-bounce term
(``j = 1``) is the exact single-scattering one of :mod:`speclight.render.laser_returns`, so the sum
over bounces is unbiased for the full multi-bounce return. Paths stop after ``max_depth - 1``
surface vertices (Mitsuba's ``max_depth`` convention, camera segment included). Limitation:
cosine sampling cannot follow the delta reflection of smooth mirrors (``specular``, a smooth
``plastic`` coat), so light that reaches the receiver through a mirror bounce of a smooth
surface is missed (as with a point light in Mitsuba's path mode); glossy surfaces are
followed, with more noise the smoother they are.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
from numpy.typing import NDArray

from speclight.render.material_channels import ChannelLayout
from speclight.render.raycast import Caster
from speclight.render.shading import VisibleHits, dot_rows, half_vectors, mirror_in_sun

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


def fcos_spectral(
    layout: ChannelLayout,
    blocks: dict[int, F64],
    wavelength_nm: F64,
    part_material: I64,
    n: F64,
    to_light: F64,
    to_viewer: F64,
) -> F64:
    """``f(to_light, to_viewer) cos(theta_light)`` (M, S) [sr-1] on the given wavelengths.

    ``part_material`` (M,) is each point's material index in ``layout``; ``blocks`` the
    block factors of its materials on these wavelengths
    (:meth:`~speclight.render.bsdfs.MaterialBsdf.block_factor`). ``n`` faces ``to_viewer``
    (two-sided surfaces); zero where the light is behind.
    """
    out = np.zeros((len(n), len(wavelength_nm)))
    cos_i, cos_o = dot_rows(n, to_light), dot_rows(n, to_viewer)
    ok = np.flatnonzero((cos_i > 0) & (cos_o > 0))
    if ok.size == 0:
        return out
    s, v, nn = to_light[ok], to_viewer[ok], n[ok]
    half = half_vectors(s, v)
    cos_h, cos_d = dot_rows(nn, half), dot_rows(s, half)
    mirror_ok = mirror_in_sun(nn, cos_o[ok], v, s)
    for k, bsdf in enumerate(layout.bsdfs):
        sel = np.flatnonzero(part_material[ok] == k)
        if sel.size:
            p = ok[sel]
            out[p] = bsdf.fcos(
                cos_i[p], cos_o[p], cos_h[sel], cos_d[sel], mirror_ok[sel], wavelength_nm,
                blocks.get(k),
            )  # fmt: skip
    return out


def _cosine_hemisphere(n: F64, rng: np.random.Generator) -> F64:
    """Directions (M, 3) drawn with pdf cos(theta)/pi about the unit normals ``n``."""
    u1, u2 = rng.random(len(n)), rng.random(len(n))
    r, phi = np.sqrt(u1), 2.0 * np.pi * u2
    x, y, z = r * np.cos(phi), r * np.sin(phi), np.sqrt(np.maximum(0.0, 1.0 - u1))
    a = np.where((np.abs(n[:, 0]) < 0.9)[:, None], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    t = np.cross(n, a)
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    b = np.cross(n, t)
    return np.asarray(x[:, None] * t + y[:, None] * b + z[:, None] * n)


def _offset_origin(pos: F64, n: F64) -> F64:
    """Start secondary rays off the surface, like Mitsuba's ``spawn_ray`` offset."""
    scale = (1.0 + np.abs(pos).max(axis=1, keepdims=True)) * 2e-5
    return np.asarray(pos + scale * n)


def multibounce_returns(
    layout: ChannelLayout,
    blocks: dict[int, F64],
    wavelength_nm: F64,
    v: VisibleHits,
    s_dir: F64,
    lit_ep: NDArray[np.bool_],
    irradiance_W_m2_nm: F64,
    caster: Caster,
    pixel_area_m2: float,
    com_body_m: F64,
    bin_edges_m: F64,
    *,
    max_depth: int,
    samples_per_pixel: int,
    seed: tuple[int, ...],
) -> Iterator[tuple[F64, F64]]:
    """The returns of bounces 2..max_depth-1 of one laser, as increments to its histograms.

    Parameters
    ----------
    layout, blocks
        Channel layout of the target and the block factors of its materials that have a
        block (plastic, RGL) on the laser's support wavelengths ``wavelength_nm`` (S,) [nm].
    v
        The batch's primary hits (:class:`~speclight.render.shading.VisibleHits`).
    s_dir, lit_ep
        (b, 3) unit vectors to the laser and (b,) whether it lights each epoch of the batch.
    irradiance_W_m2_nm
        (b, S) the laser's spectral irradiance at the target.
    caster, pixel_area_m2
        The ray caster and the area of one primary pixel [m²].
    com_body_m, bin_edges_m
        Centre of mass (3,) [m] and the uniform range-offset bin edges (nbins+1,) [m].
    max_depth, samples_per_pixel, seed
        Path length limit (Mitsuba's convention), Monte Carlo paths per pixel, and the
        entropy of the random stream (:class:`numpy.random.SeedSequence`).

    Yields
    ------
    tuple
        ``(histogram (b, S, nbins) [W sr-1 nm-1], moment (b, S) [W sr-1 nm-1 m])`` for every
        sample and bounce that returns light; the caller adds them in order.
    """
    wl = wavelength_nm
    start = np.flatnonzero(lit_ep[v.ep])
    if start.size == 0:
        return
    part_mat = layout.part_mat
    spp = max(1, int(samples_per_pixel))
    edges = bin_edges_m
    nb = len(edges) - 1
    width = (edges[-1] - edges[0]) / nb
    b, n_s = len(v.epochs), len(wl)
    for child in np.random.SeedSequence(list(seed)).spawn(spp):
        rng = np.random.default_rng(child)
        slot = v.ep[start]
        pos = v.position(start)
        n, view = v.n[start], v.o[slot]
        mat = part_mat[v.part[start]]
        path = -v.rel_o[start]  # receiver plane -> p1
        through = np.ones((start.size, n_s))
        for _ in range(2, max_depth):
            w = _cosine_hemisphere(n, rng)
            fc = fcos_spectral(layout, blocks, wl, mat, n, w, view)
            through = through * fc * np.pi / np.maximum(dot_rows(n, w), 1e-12)[:, None]
            hits = caster.intersect(_offset_origin(pos, n), w)
            keep = np.flatnonzero(hits.hit & np.any(through > 0, axis=1))
            if keep.size == 0:
                break
            slot, through, w = slot[keep], through[keep], w[keep]
            t = hits.t_m[keep]
            pos = pos[keep] + t[:, None] * w
            path = path[keep] + t
            view = -w
            n = hits.normal[keep]
            n = n * np.where(dot_rows(n, view) < 0, -1.0, 1.0)[:, None]
            mat = part_mat[hits.part[keep]]
            # next-event estimation towards the laser
            s = s_dir[slot]
            lit = np.flatnonzero(dot_rows(n, s) > 0)
            if lit.size:
                blocked = caster.occluded(pos[lit], s[lit], n[lit])
                lit = lit[~blocked]
            if lit.size:
                fl = fcos_spectral(layout, blocks, wl, mat[lit], n[lit], s[lit], view[lit])
                value = through[lit] * fl * irradiance_W_m2_nm[slot[lit]] * (pixel_area_m2 / spp)
                delta = 0.5 * (path[lit] - dot_rows(pos[lit] - com_body_m, s[lit]))
                bins = np.clip(((delta - edges[0]) / width).astype(np.int64), 0, nb - 1)
                flat_m = slot[lit, None] * n_s + np.arange(n_s)[None, :]
                h = np.bincount(
                    (flat_m * nb + bins[:, None]).ravel(), value.ravel(), minlength=b * n_s * nb
                )
                mom = np.bincount(
                    flat_m.ravel(), (value * delta[:, None]).ravel(), minlength=b * n_s
                )
                yield (
                    np.asarray(h, float).reshape(b, n_s, nb),
                    np.asarray(mom, float).reshape(b, n_s),
                )
