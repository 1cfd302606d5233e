"""Laser returns resolved in range: single-scattering render of laser light with path lengths.

Each laser is a directional light (its direction in the body frame per epoch) with a spectral
irradiance at the target. The orthographic primary rays along the line of sight are the ones of
the single-scattering Sun render (:mod:`speclight.render.single`); for every pixel that sees a
surface lit by the laser (shadow ray towards the laser unless the laser is coaxial with the
receiver), the BRDF gives the pixel's radiant intensity contribution per wavelength,
``dI = A_pix f(l, o) cos(theta_l) E(lambda)`` [W sr-1 nm-1], and its position ``p`` gives the
one-way-equivalent range offset from the centre of mass ``c`` (half of the extra optical path
transmitter -> p -> receiver compared with the path through ``c``):

    delta = -((p - c) . o + (p - c) . l) / 2      [m]

(``o``, ``l``: unit vectors from the target to the receiver and to the laser; for a coaxial
laser ``delta = -(p - c) . o``, the depth of the pixel behind the plane through ``c``; negative
= in front of the centre of mass). A return at ``delta`` arrives ``2 delta / c`` after one
from the centre of mass (Degnan 1993, "Millimeter accuracy satellite laser ranging: a review",
AGU Geodynamics Series 25, section 4, doi:10.1029/GD025p0133, on target signatures).

What is stored per epoch, light and wavelength of the laser's line (its *support*, usually one
to three bins) is the intensity histogram over range-offset bins and its first moment, not the
images, so memory is (N, S, bins) whatever the resolution. The sum over bins is the laser's
radiant intensity (the same quantity as :func:`speclight.render.render_intensity` gives for a
light of that direction and irradiance), the first moment over the sum the exact mean offset.

With ``max_depth`` > 2 the interreflections are added at their full optical path length by
:mod:`speclight.render.laser_multibounce` (Monte Carlo); the default 2 is single scattering.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from speclight.render.camera import primary_rays
from speclight.render.laser_multibounce import multibounce_returns
from speclight.render.material_channels import ChannelLayout, pixel_contributions
from speclight.render.raycast import Caster, Hits
from speclight.render.shading import (
    SUN_COS,
    VisibleHits,
    dot_rows,
    half_vectors,
    mirror_in_sun,
)
from speclight.target.parts import Target

if TYPE_CHECKING:
    from speclight.render.session import RenderSession

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]
#: Lasers closer than this to the line of sight [rad] are treated as coaxial with the receiver:
#: every pixel seen by the receiver is lit (no shadow ray). 1e-5 rad shifts a shadow ray by
#: 0.1 mm across a 10 m target, far below a pixel.
COAXIAL_RAD = 1e-5


@dataclass
class LaserLight:
    """One laser as a light source for the render.

    Attributes
    ----------
    direction_body
        (N, 3) unit vectors from the target to the transmitter, body frame (NaN: not lit).
    support
        (S,) indices into the wavelength grid where the laser line has energy.
    irradiance_W_m2_nm
        (N, S) spectral irradiance at the target on the support [W m-2 nm-1] (0: not lit).
    """

    direction_body: F64
    support: I64
    irradiance_W_m2_nm: F64


@dataclass
class LaserReturns:
    """Intensity histograms of each light: ``histogram[k]`` (N, S_k, B) [W sr-1 nm-1 per bin],
    ``moment_m[k]`` (N, S_k) [W sr-1 nm-1 m] (sum of intensity x offset), bin edges (B+1,) [m],
    and ``rendered`` (N,) True where the epoch was cast."""

    histogram: list[F64]
    moment_m: list[F64]
    bin_edges_m: F64
    rendered: NDArray[np.bool_]

    def intensity_W_sr_nm(self, k: int) -> F64:
        """(N, S_k) radiant intensity of light k on its support [W sr-1 nm-1]."""
        return np.asarray(self.histogram[k].sum(axis=2))


class LaserReturnAccumulator:
    """Accumulates laser intensity histograms from batches of primary ray hits.

    It is the ``on_hits`` callback of :func:`speclight.render.single.geometric_weights`
    (called with global epoch indices, ray origins, directions and hits, so that the Sun
    render's rays are reused), and :meth:`finish` casts the epochs it has not seen.
    """

    def __init__(
        self,
        target: Target,
        observer_dir_body: F64,
        lights: list[LaserLight],
        wavelength_nm: F64,
        bin_edges_m: F64 | None = None,
        com_body_m: F64 | None = None,
        max_depth: int = 2,
        samples_per_pixel: int = 1,
        seed: int = 0,
    ) -> None:
        self.target = target
        self.obs = np.asarray(observer_dir_body, dtype=float)
        self.lights = lights
        self.wl = np.asarray(wavelength_nm, dtype=float)
        self.com = np.zeros(3) if com_body_m is None else np.asarray(com_body_m, dtype=float)
        if bin_edges_m is None:
            from speclight.ranging.bins import range_bin_edges_m

            bin_edges_m = range_bin_edges_m(target, self.com)
        self.edges = np.asarray(bin_edges_m, dtype=float)
        self.layout = ChannelLayout(target)
        n, nb = len(self.obs), len(self.edges) - 1
        self.hist = [np.zeros((n, len(lt.support), nb)) for lt in lights]
        self.moment = [np.zeros((n, len(lt.support))) for lt in lights]
        self.rendered = np.zeros(n, dtype=bool)
        self.active = np.zeros(n, dtype=bool)
        for lt in lights:
            self.active |= np.all(np.isfinite(lt.direction_body), axis=1) & np.any(
                lt.irradiance_W_m2_nm > 0, axis=1
            )
        self.active &= np.all(np.isfinite(self.obs), axis=1)
        #: Path length limit (Mitsuba's convention): 2 = single scattering; more adds the
        #: interreflections of :mod:`speclight.render.laser_multibounce` (Monte Carlo).
        self.max_depth = int(max_depth)
        self.samples_per_pixel = int(samples_per_pixel)
        self.seed = int(seed)
        self._blocks = {k: self.layout.bsdfs[k].block_factor(self.wl) for k in self.layout.block}

    def __call__(
        self, epochs: I64, origin: F64, direction: F64, hits: Hits, caster: Caster | None = None
    ) -> None:
        """Add one batch: ``epochs`` (b,) global indices; rays and hits (b * pixels,); the
        caster that cast them (for shadow rays towards bistatic lasers)."""
        if caster is not None:
            self._caster = caster
        epochs = np.asarray(epochs, dtype=np.int64)
        b = len(epochs)
        if b == 0:
            return
        pixels = len(origin) // b
        o = self.obs[epochs]
        # compact to the rays that hit a surface facing the receiver (two-sided: flip normals)
        hit = np.flatnonzero(hits.hit)
        ep = hit // pixels
        n = hits.normal[hit]
        cos_o = np.einsum("mk,mk->m", n, o[ep])
        flip = np.where(cos_o < 0, -1.0, 1.0)
        keep = cos_o * flip > 0
        hit, ep, n, cos_o = hit[keep], ep[keep], n[keep] * flip[keep, None], (cos_o * flip)[keep]
        t = hits.t_m[hit]
        # (p - c) . o = (origin - c) . o - t: the primary rays travel along -o
        ray0 = np.einsum("bk,bk->b", origin[np.arange(b) * pixels] - self.com, o)
        view = VisibleHits(epochs, ep, o, n, cos_o, hit, t, ray0[ep] - t, hits.part[hit], origin)
        for k, light in enumerate(self.lights):
            self._light(k, light, view)
        self.rendered[epochs] = True

    def _light(self, k: int, light: LaserLight, v: VisibleHits) -> None:
        epochs, o = v.epochs, v.o
        lit_ep = np.all(np.isfinite(light.direction_body[epochs]), axis=1) & np.any(
            light.irradiance_W_m2_nm[epochs] > 0, axis=1
        )
        if not np.any(lit_ep):
            return
        s = np.where(lit_ep[:, None], light.direction_body[epochs], o)
        coaxial = np.einsum("bk,bk->b", s, o) > np.cos(COAXIAL_RAD)
        if np.all(coaxial):
            # laser along the line of sight: every seen pixel is lit, at incidence = exit
            idx = np.flatnonzero(lit_ep[v.ep])
            e_idx = v.ep[idx]
            cos_o = v.cos_o[idx]
            cos_i, cos_h, cos_d = cos_o, cos_o, np.ones_like(cos_o)
            mirror_ok = (2.0 * cos_o**2 - 1.0 >= SUN_COS).astype(float)
            delta_px = -v.rel_o[idx]
        else:
            cos_all = dot_rows(v.n, s[v.ep])
            idx = np.flatnonzero(lit_ep[v.ep] & (cos_all > 0))
            pos = v.position(idx)
            check = np.flatnonzero(~coaxial[v.ep[idx]])
            if check.size:
                blocked = self._caster.occluded(pos[check], s[v.ep[idx[check]]], v.n[idx[check]])
                good = np.ones(idx.size, dtype=bool)
                good[check[blocked]] = False
                idx, pos = idx[good], pos[good]
            e_idx = v.ep[idx]
            n_i, cos_o = v.n[idx], v.cos_o[idx]
            cos_i = cos_all[idx]
            half = half_vectors(s, o)
            cos_h = dot_rows(n_i, half[e_idx])
            cos_d = dot_rows(s, half)[e_idx]
            mirror_ok = mirror_in_sun(n_i, cos_o, o[e_idx], s[e_idx])
            # one-way-equivalent range offset of each lit pixel (module docstring)
            rel_s = dot_rows(pos - self.com, s[e_idx])
            delta_px = -0.5 * (v.rel_o[idx] + rel_s)
        mat = self.layout.part_mat[v.part[idx]]
        rows, chans, w = pixel_contributions(
            self.layout, mat, cos_i, cos_o, cos_h, cos_d, mirror_ok
        )
        radius = self.target.bounding_sphere()[1]
        pixel_area = (2.0 * radius) ** 2 / v.pixels
        if rows.size:
            self._add_single(
                k, light, epochs, s, o, e_idx[rows], chans, w * pixel_area, delta_px[rows]
            )
        if self.max_depth > 2:
            sup = light.support
            increments = multibounce_returns(
                self.layout,
                {c: f[:, sup] for c, f in self._blocks.items()},
                self.wl[sup],
                v,
                s,
                lit_ep,
                light.irradiance_W_m2_nm[epochs],
                self._caster,
                pixel_area,
                self.com,
                self.edges,
                max_depth=self.max_depth,
                samples_per_pixel=self.samples_per_pixel,
                seed=(self.seed, int(epochs[0]), k),
            )
            for hist, moment in increments:  # in order: the sums are those of one pass
                self.hist[k][epochs] += hist
                self.moment[k][epochs] += moment

    def _add_single(
        self,
        k: int,
        light: LaserLight,
        epochs: I64,
        s: F64,
        o: F64,
        e_rows: I64,
        chans: I64,
        w: F64,
        delta: F64,
    ) -> None:
        """Histogram the one-bounce contributions (epoch slot, channel, weight [m² sr-1])."""
        sup = light.support
        b, n_s = len(epochs), sup.size
        # spectral factor (b, C, S) on the laser's support, times the irradiance
        cos_half = np.sqrt(np.clip(0.5 * (1.0 + np.einsum("bk,bk->b", s, o)), 0.0, 1.0))
        factor = np.zeros((b, self.layout.n_channels, n_s))
        for c, bsdf in enumerate(self.layout.bsdfs):
            factor[:, c, :] = bsdf.main_factor(cos_half, self.wl[sup])
        for c, start in self.layout.block.items():
            blk = self._blocks[c][:, sup]
            factor[:, start : start + blk.shape[0], :] = blk[None]
        factor *= light.irradiance_W_m2_nm[epochs][:, None, :]
        value = w[:, None] * factor[e_rows, chans, :]  # (M, S)
        nb = len(self.edges) - 1
        width = (self.edges[-1] - self.edges[0]) / nb
        bins = np.clip(((delta - self.edges[0]) / width).astype(np.int64), 0, nb - 1)
        flat_m = e_rows[:, None] * n_s + np.arange(n_s)[None, :]
        h = np.bincount(
            (flat_m * nb + bins[:, None]).ravel(), value.ravel(), minlength=b * n_s * nb
        )
        self.hist[k][epochs] += h.reshape(b, n_s, nb)
        mom = np.bincount(flat_m.ravel(), (value * delta[:, None]).ravel(), minlength=b * n_s)
        self.moment[k][epochs] += mom.reshape(b, n_s)

    _caster: Caster

    def finish(self, caster: Caster, resolution_px: int, rays_per_batch: int = 1_000_000) -> None:
        """Cast the active epochs that no :meth:`__call__` has covered."""
        self._caster = caster
        todo = np.flatnonzero(self.active & ~self.rendered)
        centre, radius = self.target.bounding_sphere()
        batch = max(1, rays_per_batch // (resolution_px * resolution_px))
        for a in range(0, todo.size, batch):
            epochs = todo[a : a + batch]
            origin, direction, _ = primary_rays(centre, radius, self.obs[epochs], resolution_px)
            hits = caster.intersect(origin, direction)
            self(epochs, origin, direction, hits)

    def result(self) -> LaserReturns:
        """The accumulated histograms."""
        return LaserReturns(self.hist, self.moment, self.edges, self.rendered.copy())


def render_laser_returns(
    target: Target,
    observer_dir_body: F64,
    lights: list[LaserLight],
    wavelength_nm: F64,
    *,
    resolution_px: int = 256,
    variant: str | None = None,
    bin_edges_m: F64 | None = None,
    com_body_m: F64 | None = None,
    max_depth: int = 2,
    samples_per_pixel: int = 1,
    seed: int = 0,
    session: RenderSession | None = None,
) -> LaserReturns:
    """Laser intensity histograms over range offset, rendering every epoch itself.

    Parameters
    ----------
    target
        The target (body frame).
    observer_dir_body
        (N, 3) unit vectors from the target to the receiver, body frame.
    lights
        The lasers (see :class:`LaserLight`).
    wavelength_nm
        (L,) grid [nm].
    resolution_px
        Image size (square) over the target's bounding sphere.
    variant
        Mitsuba variant, ``"numpy"`` or ``None`` (automatic), as for ``render_intensity``;
        ignored when ``session`` is given.
    bin_edges_m
        Uniform range-offset bin edges [m] (default
        :func:`speclight.ranging.bins.range_bin_edges_m`, single-bounce span).
    com_body_m
        Centre of mass in the body frame [m] (default: the body-frame origin).
    max_depth, samples_per_pixel, seed
        ``max_depth`` > 2 adds multi-bounce returns at their full path length, traced with
        ``samples_per_pixel`` Monte Carlo paths per pixel from ``seed``
        (:mod:`speclight.render.laser_multibounce`); 2 is single scattering (exact, no noise).
    session
        The run's render session (:class:`speclight.render.session.RenderSession`): its
        variant and ray caster.

    Returns
    -------
    LaserReturns
    """
    from speclight.render.session import RenderSession

    if session is None:
        session = RenderSession.create("single", variant, target.materials)
    caster = session.caster(target)
    acc = LaserReturnAccumulator(
        target,
        observer_dir_body,
        lights,
        wavelength_nm,
        bin_edges_m,
        com_body_m,
        max_depth=max_depth,
        samples_per_pixel=samples_per_pixel,
        seed=seed,
    )
    acc.finish(caster, int(resolution_px))
    return acc.result()


__all__ = [
    "COAXIAL_RAD",
    "LaserLight",
    "LaserReturnAccumulator",
    "LaserReturns",
    "render_laser_returns",
]
