"""The single-scattering render inside Dr.Jit: one batch of epochs, channel sums out.

With a vectorised Mitsuba variant (``llvm_ad_*``, ``cuda_ad_*``) the single mode
(:mod:`speclight.render.single`) runs a batch of epochs as Dr.Jit arrays from the pixel
grid to the per-epoch channel sums: the orthographic pixel-centre rays are generated in
Dr.Jit, cast with ``scene.ray_intersect``, their normals turned toward the observer,
shadow-tested with ``scene.ray_test`` toward the Sun, and every hit's channel weights
(:class:`~speclight.render.material_channels.ChannelLayout`: main channels, the blocks of a
plastic's 33 x 33 base nodes or a lab table's extension, roughness derivatives) are
evaluated by the models' own weight functions on Dr.Jit arrays
(:mod:`speclight.render.kernel_ops`) and summed per epoch and channel in the same pass. Only
the (epochs, channels) sums come back to numpy, where the spectra are one matrix product
(exact in wavelength, as before). Dr.Jit fuses each stage into one kernel: ray generation
with the primary cast, shading with the shadow cast, weights with the reduction.

The shading is done in float64 from the float32 intersections (as the numpy path does), so
each pixel's weight equals the numpy path's to float64 rounding; the pixel and shadow rays
are the numpy path's to the bit (the same float64 arithmetic rounded to float32).

**Deterministic sums.** Atomic float additions would sum in an order that depends on the
threads' schedule. The sums are instead fixed point, made exact with integer atomics and so
independent of the order (bit-for-bit reproducible on any thread count), in two passes (the
rays are cast and the weights evaluated once):

1. with the cast and the shading, every lane's weights are evaluated (each lane only its
   own material's main weight: one ``dr.switch`` over the groups of :func:`_groups`) and
   stored with their channels, and the largest |weight| of every (epoch, channel) sum found
   by an atomic maximum of the high 32 bits of its float64 (a maximum is order-independent
   too);
2. from the stored weights, every weight times the power of two 2^k of its sum (exact)
   that puts that largest weight below 2^bits (:func:`fraction_bits`: 76 at 256 px),
   rounded to a whole number held in two 64-bit integers (the high part, the low 32 bits),
   summed with integer atomics.

Each pixel's weight is rounded to at most 2^-bits of its sum's largest weight, so a sum is
within ``pixels * 2^-bits`` of that weight of the exact sum (2^-60 at 256 px, below
float64's 2^-53): float64-relative precision per (epoch, channel) at any magnitude, the
far tails of a Beckmann lobe (1e-12 sr-1) or a nearly dark epoch as well as a glint. Below
float64's smallest normal number (2.2e-308) Dr.Jit's ``exp`` returns 0 where numpy's returns
a subnormal: such weights count as 0 here. A weight that is not finite sends its batch
through the numpy path (which gives the same infinity or NaN).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.render.camera import image_axes, pixel_grid
from speclight.render.kernel_ops import drjit_ops
from speclight.render.material_channels import ChannelLayout
from speclight.render.raycast import MitsubaCaster
from speclight.render.shading import SUN_COS, half_vectors
from speclight.render.variant import activate
from speclight.target.parts import Target

F64 = NDArray[np.float64]
_WORD = 2.0**32


def kernel_supported(caster: MitsubaCaster, layout: ChannelLayout) -> bool:
    """True when :class:`SingleKernel` can render with the Mitsuba ``caster``: every
    material's weights written for the kernel
    (:meth:`~speclight.render.bsdfs.MaterialBsdf.in_kernel`)."""
    return all(b.in_kernel() for b in layout.bsdfs)


class SingleKernel:
    """Per-epoch channel sums of batches of epochs, in Dr.Jit (module doc).

    Parameters
    ----------
    target
        The target (body frame).
    caster
        Its Mitsuba caster (the scene and the part of every triangle).
    layout
        The channels to sum.
    resolution_px
        Image size (square) covering the target's bounding sphere.
    """

    def __init__(
        self, target: Target, caster: MitsubaCaster, layout: ChannelLayout, resolution_px: int
    ) -> None:
        self.mi = mi = activate(caster.name)
        import drjit as dr

        self.dr, self.caster, self.layout = dr, caster, layout
        self.ops = drjit_ops(dr, mi.Float64, mi.UInt32)
        self.centre, self.radius = target.bounding_sphere()
        self.pixels = resolution_px * resolution_px
        x, y = pixel_grid(resolution_px, self.radius)
        self.x, self.y = mi.Float64(x), mi.Float64(y)
        self.face_part = mi.UInt32(caster.face_part) if len(caster.face_part) else None
        self.part_mat = mi.UInt32(np.asarray(layout.part_mat))
        #: Bits of each fixed-point sum below its largest weight (module doc).
        self.fraction_bits = fraction_bits(self.pixels)

    def _epoch(self, values: F64, e: Any) -> list[Any]:
        """The three components of per-epoch vectors ``values`` (b, 3) at every ray."""
        f = self.mi.Float64
        return [self.dr.gather(f, f(np.ascontiguousarray(values[:, c])), e) for c in range(3)]

    def _ray(self, origin: list[Any], direction: list[Any]) -> Any:
        """Mitsuba's float32 rays from float64 components (rounded to nearest)."""
        mi = self.mi
        return mi.Ray3f(
            mi.Point3f(*[mi.Float(v) for v in origin]),
            mi.Vector3f(*[mi.Float(v) for v in direction]),
        )

    def channel_sums(self, sun_dir: F64, obs_dir: F64) -> F64 | None:
        """Channel sums (b, C) [sr-1] over the pixels (weights, not yet times the pixel
        area) of a batch of epochs; None when a weight does not fit the fixed-point sums."""
        mi, dr = self.mi, self.dr
        activate(self.caster.name)  # the scene's variant, whatever ran since
        f64, u32 = mi.Float64, mi.UInt32
        b, pixels = len(sun_dir), self.pixels
        ray = dr.arange(u32, b * pixels)
        e = ray // pixels
        p = ray - e * pixels
        right, up = image_axes(obs_dir)
        o, s = self._epoch(obs_dir, e), self._epoch(sun_dir, e)
        r_e, u_e = self._epoch(right, e), self._epoch(up, e)
        x, y = dr.gather(f64, self.x, p), dr.gather(f64, self.y, p)
        reach = 2.0 * self.radius
        origin = [float(self.centre[c]) + x * r_e[c] + y * u_e[c] + reach * o[c] for c in range(3)]
        si = self.caster.scene.ray_intersect(
            self._ray(origin, [-v for v in o]),
            ray_flags=mi.RayFlags.Minimal,
            coherent=False,  # Embree's coherent mode picks other triangles at shared edges
        )
        hit = si.is_valid()
        n = [f64(si.n.x), f64(si.n.y), f64(si.n.z)]
        norm = dr.maximum(dr.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), 1e-30)
        n = [v / norm for v in n]
        cos_o = n[0] * o[0] + n[1] * o[1] + n[2] * o[2]
        flip = dr.select(cos_o < 0, f64(-1.0), f64(1.0))  # thin sheets reflect on both faces
        n = [v * flip for v in n]
        cos_o = cos_o * flip
        cos_i = n[0] * s[0] + n[1] * s[1] + n[2] * s[2]
        lit = hit & (cos_i > 0) & (cos_o > 0)
        t = f64(si.t)
        pos = [origin[c] - t * o[c] for c in range(3)]
        scale = 1.0 + dr.maximum(dr.maximum(dr.abs(pos[0]), dr.abs(pos[1])), dr.abs(pos[2]))
        shadow = [pos[c] + scale * 2e-5 * n[c] for c in range(3)]
        blocked = self.caster.scene.ray_test(self._ray(shadow, s), active=lit)
        lit = lit & ~blocked
        half = half_vectors(sun_dir, obs_dir)
        h = self._epoch(half, e)
        cos_h = n[0] * h[0] + n[1] * h[1] + n[2] * h[2]
        cos_d = dr.gather(f64, f64(np.einsum("nk,nk->n", sun_dir, half)), e)
        mirror = [2.0 * cos_o * n[c] - o[c] for c in range(3)]
        glint = mirror[0] * s[0] + mirror[1] * s[1] + mirror[2] * s[2] >= SUN_COS
        mirror_ok = dr.select(glint, f64(1.0), f64(0.0))
        part = self._parts(si)
        mat = dr.gather(u32, self.part_mat, part, hit)
        return self._sums(b, e, mat, lit, (cos_i, cos_o, cos_h, cos_d, mirror_ok))

    def _parts(self, si: Any) -> Any:
        """Part index of every hit (the triangle's part, or the sphere's)."""
        mi, dr = self.mi, self.dr
        part = dr.zeros(mi.UInt32, dr.width(si.t))
        if self.face_part is not None:
            part = dr.gather(mi.UInt32, self.face_part, si.prim_index, si.is_valid())
        for shape, k in self.caster.shape_part:
            part = dr.select(si.shape == mi.ShapePtr(shape), k, part)
        return part

    def _entries(self, mat: Any, lit: Any, cosines: tuple[Any, ...]) -> list[tuple[Any, Any, Any]]:
        """Every lane's (channel, weight [sr-1], active) of every model's channels: main
        weights, roughness derivatives, block entries (lazy Dr.Jit expressions)."""
        mi, dr, layout, ops = self.mi, self.dr, self.layout, self.ops
        cos_i, cos_o, cos_h, cos_d = cosines[:4]
        entries: list[tuple[Any, Any, Any]] = []

        def lanes(ks: list[int]) -> Any:
            """The lit pixels of materials ``ks``."""
            mine = mat == ks[0]
            for k in ks[1:]:
                mine = mine | (mat == k)
            return lit & mine

        def per_material(channel: dict[int, int]) -> Any:
            """Each lane's channel from a material -> channel table."""
            table = np.zeros(len(layout.bsdfs), np.uint32)
            for k, c in channel.items():
                table[k] = c
            return dr.gather(mi.UInt32, mi.UInt32(table), mat)

        groups = _groups(layout, main=True)
        group_of = {k: g for g, ks in enumerate(groups) for k in ks}

        def main(ks: list[int]) -> Any:
            """The main weight (and roughness derivative, 0 without) of materials ``ks``."""
            bsdf = layout.bsdfs[ks[0]]

            def weights(i: Any, o: Any, h: Any, d: Any, m: Any, _active: Any) -> tuple[Any, Any]:
                weight = bsdf.main_weight(i, o, h, d, m, ops)
                if ks[0] not in layout.grad:
                    return weight, dr.zeros(mi.Float64, dr.width(weight))
                return weight, bsdf.roughness_derivative(i, o, h, ops)

            return weights

        # each lit lane evaluates its own group's weights only (one call per group and
        # packet of lanes, not every group's formula on every lane)
        if len(groups) == 1:
            weight, dw = main(groups[0])(*cosines, lit)
        else:
            targets = [main(ks) for ks in groups]
            weight, dw = dr.switch(per_material(group_of), targets, *cosines, lit)
        entries.append((mat, weight, lit))
        if layout.grad:
            entries.append((per_material(layout.grad), dw, lanes(sorted(layout.grad))))
        for ks in _groups(layout, main=False):
            bsdf, mine = layout.bsdfs[ks[0]], lanes(ks)
            start = per_material(layout.block)
            for node, weight in bsdf.block_entries(cos_i, cos_o, cos_h, cos_d, ops):
                entries.append((start + node, weight, mine))
        return entries

    def _sums(self, b: int, e: Any, mat: Any, lit: Any, cosines: tuple[Any, ...]) -> F64 | None:
        """Every channel's weights of the lit pixels, summed per epoch in fixed point
        relative to each sum's largest weight (module doc); None for a weight not finite."""
        mi, dr = self.mi, self.dr
        n_ch = self.layout.n_channels
        entries = [(e * n_ch + c, w, a) for c, w, a in self._entries(mat, lit, cosines)]
        # pass 1: the largest |weight| of every (epoch, channel), as the high 32 bits of its
        # float64 (sign, 11 exponent bits, 20 mantissa bits: ordered as the magnitudes are)
        peak = dr.zeros(mi.UInt32, b * n_ch)
        for index, weight, active in entries:
            bits = dr.reinterpret_array(mi.UInt64, dr.abs(weight)) >> 32
            dr.scatter_reduce(dr.ReduceOp.Max, peak, mi.UInt32(bits), index, active)
        dr.schedule(*[x for entry in entries for x in entry])  # stored for pass 2
        dr.eval(peak)
        shift = scale_exponents(np.asarray(peak), self.fraction_bits)
        if shift is None:
            return None
        # pass 2 (from the stored weights): every weight times 2^shift of its sum (exact),
        # rounded to a whole number held in two words (the high part's floor and the low
        # 32 bits), integer atomics
        high = dr.zeros(mi.Int64, b * n_ch)
        low = dr.zeros(mi.Int64, b * n_ch)
        shifts = mi.Int32(shift)
        for index, weight, active in entries:
            k = dr.gather(mi.Int32, shifts, index, active)
            half = k >> 1  # two factors: 2^k alone leaves float64's range
            v = weight * self._power_of_two(half) * self._power_of_two(k - half)
            hi = dr.floor(v * (1.0 / _WORD))
            lo = dr.round(v - hi * _WORD)
            dr.scatter_reduce(dr.ReduceOp.Add, high, mi.Int64(hi), index, active)
            dr.scatter_reduce(dr.ReduceOp.Add, low, mi.Int64(lo), index, active)
        dr.eval(high, low)
        whole = np.asarray(high, dtype=np.float64) * _WORD + np.asarray(low, dtype=np.float64)
        return np.ldexp(whole, -shift).reshape(b, n_ch)

    def _power_of_two(self, k: Any) -> Any:
        """2^k as float64 for whole ``k`` in [-1022, 1023] (its exponent bits)."""
        mi, dr = self.mi, self.dr
        return dr.reinterpret_array(mi.Float64, mi.UInt64(mi.Int64(k + 1023)) << 52)


def fraction_bits(pixels: int) -> int:
    """Bits of a fixed-point sum over ``pixels`` below its largest weight (module doc): the
    sum of the high words of up to 4 entries per pixel and channel stays below 2^62."""
    return 94 - int(np.ceil(np.log2(4 * max(pixels, 1))))


def scale_exponents(peak_bits: NDArray[np.uint32], bits: int) -> NDArray[np.int32] | None:
    """The power of two ``k`` per sum that scales its weights below 2^``bits``, from the high
    32 bits of the largest |weight| (``peak_bits``); None where that weight is not finite
    (exponent bits all ones: infinity or NaN)."""
    exponent = (peak_bits >> 20).astype(np.int32)  # biased: |w| < 2^(exponent - 1022)
    if np.any(exponent == 2047):
        return None
    return (bits + 1022 - exponent).astype(np.int32)


def _groups(layout: ChannelLayout, main: bool) -> list[list[int]]:
    """The materials whose main weights (and roughness derivatives), or whose block entries
    (``main`` False: materials with a block only), are one function of the cosines
    (:meth:`~speclight.render.bsdfs.MaterialBsdf.kernel_key`): the kernel evaluates each
    group once over the pixels of all its materials."""
    groups: dict[Any, list[int]] = {}
    for k, bsdf in enumerate(layout.bsdfs):
        if main:
            groups.setdefault((bsdf.kernel_key(), k in layout.grad), []).append(k)
        elif k in layout.block:
            groups.setdefault(bsdf.kernel_key(block=True), []).append(k)
    return list(groups.values())


__all__ = ["SingleKernel", "fraction_bits", "kernel_supported", "scale_exponents"]
