"""The single-scattering render's channels: every material's pixel weights, side by side.

Each material contributes through *channels* (:mod:`speclight.render.bsdfs`): a geometric
weight per pixel [sr-1] (summed over pixels times the pixel area) and a spectral factor [1].
The main channel of every material has a factor that depends only on the epoch (through the
half-phase angle); a model that does not factorise so adds a block of channels with
epoch-independent factors (a ``plastic``'s diffuse base binned in (cos theta_i,
cos theta_o), an RGL file's wavelength nodes). :class:`ChannelLayout` numbers the channels
of a target's materials; :func:`pixel_contributions` gives every pixel's weights.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from speclight.render.bsdfs import MaterialBsdf, material_bsdf
from speclight.target.materials import Material
from speclight.target.parts import Target

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


#: Primary rays per single-mode batch without RGL materials.
RAYS_PER_BATCH = 1_000_000
#: Pixel contributions (pixel, channel, weight) held at once in a single-mode batch with RGL
#: materials (about 40 bytes each).
CONTRIBUTIONS_PER_BATCH = 4_000_000


def rays_per_batch(materials: tuple[Material, ...] | list[Material]) -> int:
    """Primary rays per single-mode batch: :data:`RAYS_PER_BATCH`, fewer with RGL materials
    (one contribution per pixel and wavelength node of the file) so that a batch holds about
    :data:`CONTRIBUTIONS_PER_BATCH`; at least one epoch is always cast at once."""
    nodes = max((material_bsdf(m, "single").entries_per_pixel() for m in materials), default=0)
    return min(RAYS_PER_BATCH, CONTRIBUTIONS_PER_BATCH // (1 + nodes))


class ChannelLayout:
    """Channel layout: main channel m for material m, then a block per plastic or RGL material.

    Blocks (:func:`speclight.render.material_block_size`) carry what does not
    factorise: K*K channels of a plastic's diffuse base, one channel per wavelength node of an
    RGL file.
    """

    def __init__(self, target: Target) -> None:
        self.mats = list(target.materials)
        #: Each material's evaluator (an InputError for a model the single mode lacks).
        self.bsdfs: list[MaterialBsdf] = [material_bsdf(m, "single") for m in self.mats]
        self.part_mat = target.part_material_index
        self.block: dict[int, int] = {}
        c = len(self.mats)
        for k, bsdf in enumerate(self.bsdfs):
            extra = bsdf.block_size()  # plastic base, RGL wavelength nodes
            if extra:
                self.block[k] = c
                c += extra
        self.n_channels = c
        #: (C,) True for the channels of light from outside a measured table's support.
        self.outside = np.zeros(c, dtype=bool)
        for k, start in self.block.items():
            mask = self.bsdfs[k].outside_support()
            self.outside[start : start + mask.size] = mask


def pixel_contributions(
    layout: ChannelLayout, mat: I64, cos_i: F64, cos_o: F64, cos_h: F64, cos_d: F64, mirror_ok: F64
) -> tuple[I64, I64, F64]:
    """(pixel position in the input, channel, weight [sr-1]) of every contribution.

    ``mat`` (M,) is each pixel's material index; the cosines are those of
    :mod:`speclight.render.shading`; ``mirror_ok`` (M,) is 1 where a smooth mirror glints.
    """
    rows, chans, weights = [], [], []
    for k, bsdf in enumerate(layout.bsdfs):
        sel = np.flatnonzero(mat == k)
        if sel.size == 0:
            continue
        w = bsdf.main_weight(cos_i[sel], cos_o[sel], cos_h[sel], cos_d[sel], mirror_ok[sel])
        rows.append(sel)
        chans.append(np.full(sel.size, k))
        weights.append(w)
        if k in layout.block:
            r, c, bw = bsdf.block_weights(cos_i[sel], cos_o[sel], cos_h[sel], cos_d[sel])
            rows.append(sel[r])
            chans.append(layout.block[k] + c)
            weights.append(bw)
    if not rows:
        return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0)
    return np.concatenate(rows), np.concatenate(chans), np.concatenate(weights)
