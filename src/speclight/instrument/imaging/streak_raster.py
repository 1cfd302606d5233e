"""Light of a moving source on the detector: points along its path, blurred by the PSF.

Plain arrays. Pixel coordinates are numpy's and astropy's: ``x`` along columns, ``y``
along rows, pixel ``(row j, column i)`` centred at ``(x, y) = (i, j)`` and covering
``[i - 1/2, i + 1/2]``. A source's path during an exposure is a list of points, each with
the light (electrons) it collects in its share of the exposure. They are spread on a fine
grid of ``oversampling`` x ``oversampling`` sub-pixels per pixel (bilinear weights, which
keep the light and its centroid exactly), convolved with the PSF drawn on that grid
(:func:`~speclight.instrument.imaging.psf.psf_kernel`, pixel response included) and summed
back into pixels. A long path is cut into pieces of at most :data:`PIECE_PX` pixels so that
each piece's fine grid stays small.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.signal import fftconvolve

F64 = NDArray[np.float64]

#: Longest piece of a path rasterised on one fine grid [pixels along each axis].
PIECE_PX = 256


def splat_bilinear(shape: tuple[int, int], u: F64, v: F64, weights: F64) -> F64:
    """Spread weights at fractional grid positions onto a grid (bilinear).

    Parameters
    ----------
    shape
        (rows, columns) of the grid.
    u, v
        (P,) positions along columns and rows, in grid cells (cell centres at integers).
    weights
        (P,) what each point carries.

    Returns
    -------
    numpy.ndarray
        The grid; points within one cell of the edge lose the share that falls outside.
    """
    ny, nx = shape
    u = np.asarray(u, dtype=np.float64)
    v = np.asarray(v, dtype=np.float64)
    w = np.asarray(weights, dtype=np.float64)
    i0 = np.floor(u).astype(np.int64)
    j0 = np.floor(v).astype(np.int64)
    fu, fv = u - i0, v - j0
    out = np.zeros(ny * nx, dtype=np.float64)
    for di, wi in ((0, 1.0 - fu), (1, fu)):
        for dj, wj in ((0, 1.0 - fv), (1, fv)):
            i, j = i0 + di, j0 + dj
            inside = (i >= 0) & (i < nx) & (j >= 0) & (j < ny)
            out += np.bincount(
                (j * nx + i)[inside], weights=(w * wi * wj)[inside], minlength=ny * nx
            )
    return out.reshape(ny, nx)


def _pieces(x: F64, y: F64) -> list[slice]:
    """Consecutive runs of points, each spanning at most PIECE_PX pixels in x and in y."""
    out, start = [], 0
    while start < x.size:
        xs, ys = x[start:], y[start:]
        span = np.maximum(  # the run's box size, non-decreasing with the run's length
            np.maximum.accumulate(xs) - np.minimum.accumulate(xs),
            np.maximum.accumulate(ys) - np.minimum.accumulate(ys),
        )
        end = start + max(int(np.searchsorted(span, PIECE_PX, side="right")), 1)
        out.append(slice(start, end))
        start = end
    return out


def add_source(
    image: F64,
    x_px: F64,
    y_px: F64,
    electrons: F64,
    kernel: F64,
    oversampling: int,
) -> float:
    """Add a (moving) source's light to a frame, in place.

    Parameters
    ----------
    image
        (rows, columns) frame [electrons], changed in place.
    x_px, y_px
        (P,) positions of the source along its path [pixels].
    electrons
        (P,) light collected at each position [electrons].
    kernel
        (K, K) PSF (or PSF convolved with the source's shape) on the fine grid, K odd,
        centred on its middle pixel.
    oversampling
        Fine pixels per pixel along each axis.

    Returns
    -------
    float
        The electrons that landed on the frame (less than the sum of ``electrons`` where
        light falls off the edges or outside the kernel).
    """
    ny, nx = image.shape
    n = int(oversampling)
    x = np.asarray(x_px, dtype=np.float64)
    y = np.asarray(y_px, dtype=np.float64)
    e = np.asarray(electrons, dtype=np.float64)
    reach = int(np.ceil((kernel.shape[0] // 2 + 1) / n))  # kernel half-width [px]
    ok = (
        np.isfinite(x)
        & np.isfinite(y)
        & (e > 0)
        & (x > -0.5 - reach)
        & (x < nx - 0.5 + reach)
        & (y > -0.5 - reach)
        & (y < ny - 0.5 + reach)
    )
    x, y, e = x[ok], y[ok], e[ok]
    landed = 0.0
    for part in _pieces(x, y) if x.size else []:
        px, py, pe = x[part], y[part], e[part]
        bx0 = int(np.floor(px.min())) - reach
        by0 = int(np.floor(py.min())) - reach
        bw = int(np.ceil(px.max())) + reach - bx0 + 1
        bh = int(np.ceil(py.max())) + reach - by0 + 1
        fine = splat_bilinear(
            (bh * n, bw * n), (px - bx0 + 0.5) * n - 0.5, (py - by0 + 0.5) * n - 0.5, pe
        )
        blurred = fftconvolve(fine, kernel, mode="same")
        stamp = blurred.reshape(bh, n, bw, n).sum(axis=(1, 3))
        # the part of the stamp on the detector
        x0, y0 = max(bx0, 0), max(by0, 0)
        x1, y1 = min(bx0 + bw, nx), min(by0 + bh, ny)
        if x1 <= x0 or y1 <= y0:
            continue
        piece = stamp[y0 - by0 : y1 - by0, x0 - bx0 : x1 - bx0]
        image[y0:y1, x0:x1] += piece
        landed += float(piece.sum())
    return landed
