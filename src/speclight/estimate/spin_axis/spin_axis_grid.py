"""The misfit of every spin-axis candidate of a grid: lookups and sums over the epochs.

The lookup is that of :mod:`.spin_axis_lookup` (spin-frame grid, nearest polar and azimuth
cell, linear in phase angle and roll, the ``n_phases`` phases of one axis and epoch one
contiguous window of the grid); what this module adds is how the work is laid out:

* **Indices once per chunk of axes.** The spin-frame coordinates, grid rows and corner
  weights of a chunk of axes x all epochs are computed in one vectorised call
  (:func:`.spin_axis_corners.lookup_corners`); the intensity and the ranging channels of a
  coaxial (laser) pass share them.
* **Sums over the epochs** ``sum p``, ``sum p^2``, ``sum p y`` of the intensity term
  (:func:`misfit_from_sums`) and, for the ranging term, ``sum (o - o_meas)^2`` of the band
  offsets, whose table holds ``o = M / R`` per grid cell (the ranging map is one geometry,
  phase angle 0, so its lookup is a single corner and the offset of the looked-up cell is
  the ratio of the cell's channels, as a ratio after the lookup would be; a ranging map of
  several geometries would interpolate the offsets rather than the channels). Two ways:

  - **compiled** (where numba is installed, :mod:`.spin_axis_window_sums`): one loop per
    axis reads each corner window from the table once and adds its products to the sums,
    no intermediate arrays (2.3-3.1 times less CPU time, BENCHMARKS.md);
  - **numpy blocks**: the grid ``values`` (rows, 2 n_phases, C) viewed as one row of
    ``n_phases x C`` contiguous floats per possible window start (:func:`window_view`, no
    copy), so a lookup gathers whole windows (one ``memcpy`` each); blocks of a few axes
    (:data:`BLOCK_BYTES` of gathered floats, about the second-level cache), so the gathered
    windows, their products and their sums stay in the cache; each sum one float32 pass
    (``add.reduce``, ``einsum`` with the product fused).
* **Threads over the chunks** on request (``workers``).

Accuracy: float32 from the table to the sums over the epochs, float64 from there (the misfit
of :func:`misfit_from_sums`). tests/estimate/test_spin_axis_grid.py compares the whole misfit
surface of both ways with a float64 computation one candidate at a time (largest difference
4e-7 against a float32 rounding bound of ``8 T eps32``) and the two ways with each other.
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.spin_axis.spin_axis_corners import (
    Corners,
    EpochFrames,
    epoch_frames,
    lookup_corners,
)
from speclight.estimate.spin_axis.spin_axis_lookup import EpochGeometry, SpinFrameMap, axis_frames
from speclight.estimate.spin_axis.spin_axis_ranging import RangingTerm, coaxial
from speclight.estimate.spin_axis.spin_axis_window_sums import compiled_available, epoch_sums

F64 = NDArray[np.float64]
F32 = NDArray[np.float32]
I64 = NDArray[np.int64]
#: Gathered floats per block of axes [bytes]: about the second-level cache of one core.
BLOCK_BYTES = 1024**2


def misfit_from_sums(s1: F64, s2: F64, sy: F64, yy: F64, n_t: int) -> F64:
    """Mean squared difference of mean-normalised curves from the sums over epochs.

    ``sum_t (p / mean p - y_n)^2 = s2 / pm^2 - 2 sy / pm + yy`` with ``pm = s1 / T``.

    Parameters
    ----------
    s1, s2, sy
        ``sum p``, ``sum p^2`` and ``sum p y_n`` over the epochs (..., B, K).
    yy
        ``sum y_n^2`` (B,).
    n_t
        Epochs ``T``.
    """
    with np.errstate(invalid="ignore", divide="ignore"):
        pm = s1 / n_t
        e = s2 / pm**2 - 2 * sy / pm + yy[:, None]
    e = np.where(pm > 0, e, np.inf)
    return np.asarray(np.sum(e, axis=-2) / (n_t * s1.shape[-2]))


def window_view(values: F32) -> F32:
    """``values`` (..., 2K, C) as (rows x 2K - K + 1, K C): row ``r`` is the window of ``K``
    cells that starts at flat cell ``r`` (a strided view, no copy)."""
    v = np.ascontiguousarray(values, dtype=np.float32)
    k2, c = v.shape[-2], v.shape[-1]
    k = k2 // 2
    n_cells = v.size // c
    item = v.itemsize
    return np.lib.stride_tricks.as_strided(
        v.reshape(-1), shape=(n_cells - k + 1, k * c), strides=(c * item, item), writeable=False
    )


def gather(table: F32, corners: Corners, sl: slice, fill: float = np.nan) -> F32:
    """Interpolated windows (n, K C) of the lookups ``sl`` of ``corners`` (``fill`` where
    bad)."""
    if corners.weights is None:
        out = table[corners.rows[sl, 0]]
    else:  # (n, corners, K C) weighted and summed over the corners: (1 x c) @ (c x K C)
        w = corners.weights[sl]
        out = np.matmul(w[:, None, :], table[corners.rows[sl]])[:, 0]
    bad = corners.bad[sl]
    if bad.any():
        out[bad] = fill
    return np.asarray(out)


def _offset_table(sfm: SpinFrameMap, n_b: int) -> tuple[F32, F32]:
    """Rate channels ``R`` and band offsets ``M / R`` [m] (0 where ``R <= 0``) of a ranging
    spin-frame map of channels ``[R..., M...]``, each (..., 2K, B), contiguous float32."""
    s = np.ones(2 * n_b) if sfm.scale is None else np.asarray(sfm.scale, dtype=float)
    r = np.ascontiguousarray(sfm.values[..., :n_b])
    m = sfm.values[..., n_b:]
    off = np.zeros(r.shape, dtype=np.float32)
    np.divide(m, r, out=off, where=r > 0)
    off *= (s[n_b:] / s[:n_b]).astype(np.float32)  # undo the spin-frame map's scaling
    return r, off


@dataclass(frozen=True)
class _Table:
    """A spin-frame table (..., 2K, C) contiguous float32 as the two loops read it: ``flat``
    (cell ``r`` at ``flat[r C : (r + 1) C]``) for the compiled loop, ``windows``
    (:func:`window_view`, a view of the same memory) for numpy's gathers."""

    flat: F32
    width: int
    windows: F32


def _table(values: F32) -> _Table:
    """:class:`_Table` of ``values`` (copied only if not contiguous float32)."""
    v = np.ascontiguousarray(values, dtype=np.float32)
    return _Table(v.reshape(-1), int(v.shape[-1]), window_view(v))


@dataclass(frozen=True)
class _Pass:
    """The per-search constants of :func:`grid_pass`."""

    sfm: SpinFrameMap
    table: _Table  # the intensity channels
    ef: EpochFrames
    yn_tiled: F32  # (T, K B) mean-normalised measured curves, tiled over the phases
    yy: F64  # (B,) sum over the epochs of their squares
    n_b: int
    block_axes: int
    ranging: _Ranging | None
    compiled: bool  # sums by the compiled loop of :mod:`.spin_axis_window_sums`


@dataclass(frozen=True)
class _Ranging:
    """What the ranging term needs: its map, epochs and offset table, the measured offsets."""

    sfm: SpinFrameMap
    ef: EpochFrames  # coaxial: lit from the observer's direction
    offsets: _Table  # the offset table
    meas_tiled: F32  # (T, K B): measured offsets, 0 where unmeasured, tiled over the phases
    ok_tiled: F32 | None  # (T, K B) 1/0, or None where every offset is measured
    norm: float  # number measured x mean square of the measured offsets
    shares_rates: bool  # the intensity is the laser light of the same map


def grid_pass(
    sfm: SpinFrameMap,
    geo: EpochGeometry,
    y: F64,
    ra_all: F64,
    dec_all: F64,
    chunk: int,
    progress: Callable[[int, int], None] | None = None,
    ranging: RangingTerm | None = None,
    block_bytes: int = BLOCK_BYTES,
    workers: int = 1,
    period_s_axes: F64 | None = None,
    compiled: bool | None = None,
) -> tuple[F64, F64 | None]:
    """Intensity term (A, K) and ranging term (A, K) or None of the axes ``ra_all, dec_all``.

    ``chunk``: axes whose lookup indices are computed in one call (blocks of about
    ``block_bytes`` of gathered floats within it, numpy path); ``workers``: threads over the
    chunks (the compiled loop, numpy's gathers, ufuncs and einsum release the GIL; default 1:
    on the shared 2-core machine of BENCHMARKS.md two threads were not faster). The result
    does not depend on ``chunk``, ``block_bytes`` or ``workers``, and on ``compiled`` only to
    float32 rounding.

    Parameters
    ----------
    sfm
        The map in the spin frame.
    geo
        Sun and observer directions and times of the epochs.
    y
        Measured band light curves (T, B).
    ra_all, dec_all
        The axes [deg] (A,).
    chunk
        Axes per lookup call.
    progress
        Called with (done, total) axes, or None.
    ranging
        The range-offset term, or None.
    block_bytes
        Gathered floats per block [bytes].
    workers
        Threads over the chunks.
    period_s_axes
        Each axis's own rotation period [s] (A,) (a synodic period turned sidereal,
        :mod:`.spin_axis_period`; NaN: no candidate, infinite misfit), or None for
        ``geo.period_s``.
    compiled
        Sums over the epochs by the compiled loop of :mod:`.spin_axis_window_sums` (True;
        needs numba) or by numpy blocks (False); None: compiled where numba is installed.
    """
    n_t, n_b = y.shape
    n_k = sfm.n_phases
    yn = (y / np.mean(y, axis=0)).astype(np.float32)
    rng = None
    shares = ranging is not None and ranging.shares_rates
    if ranging is not None:
        r_tab, o_tab = _offset_table(ranging.sfm, ranging.n_bands)
        meas = ranging.offset_m
        ok = np.isfinite(meas)
        norm = float(ok.sum() * np.mean(meas[ok] ** 2)) if ok.any() else 0.0
        rng = _Ranging(
            ranging.sfm,
            epoch_frames(coaxial(geo), ranging.sfm.phase_angle_deg),
            _table(o_tab),
            np.tile(np.where(ok, meas, 0.0).astype(np.float32), (1, n_k)),
            None if ok.all() else np.tile(ok.astype(np.float32), (1, n_k)),
            norm,
            shares,
        )
    ps = _Pass(
        sfm,
        _table(r_tab if shares else sfm.values),
        epoch_frames(geo, sfm.phase_angle_deg),
        np.tile(yn, (1, n_k)),
        np.sum(yn.astype(float) ** 2, axis=0),
        n_b,
        max(1, int(block_bytes // (n_t * n_k * n_b * 4))),
        rng,
        compiled_available() if compiled is None else bool(compiled),
    )
    n_axes = ra_all.size
    e_i = np.empty((n_axes, n_k))
    e_r = None if ranging is None else np.empty((n_axes, n_k))
    chunk = max(1, int(chunk))
    starts = range(0, n_axes, chunk)

    def one(start: int) -> int:
        stop = min(start + chunk, n_axes)
        turn = None
        if period_s_axes is not None:
            per = period_s_axes[start:stop, None]
            with np.errstate(invalid="ignore"):
                turn = 2 * np.pi * np.mod(geo.t_s[None] / per, 1.0)
        frames = axis_frames(ra_all[start:stop], dec_all[start:stop])
        e_i[start:stop], er = _chunk_terms(ps, frames, turn)
        if period_s_axes is not None:
            gone = ~np.isfinite(period_s_axes[start:stop])
            e_i[start:stop][gone] = np.inf
        if e_r is not None and er is not None:
            e_r[start:stop] = er
        return stop

    n_workers = max(1, int(workers))
    with ThreadPoolExecutor(n_workers) as pool:
        for stop in (map if n_workers == 1 else pool.map)(one, starts):  # in order
            if progress is not None:
                progress(stop, n_axes)
    return e_i, e_r


def _chunk_terms(ps: _Pass, frames: F64, turn: F64 | None) -> tuple[F64, F64 | None]:
    """Both terms (A, K) of a chunk of axes, by the compiled loop or numpy blocks
    (``turn``: the axes' own spin turns (A, T) [rad], or None)."""
    n_ax, n_t, n_b, n_k = frames.shape[0], ps.yn_tiled.shape[0], ps.n_b, ps.sfm.n_phases
    rg = ps.ranging
    if turn is not None:
        turn = np.nan_to_num(turn)  # axes without a period: any lookup, marked afterwards
    c_r = None if rg is None else lookup_corners(rg.sfm, rg.ef, frames, turn)
    c_i = c_r if rg is not None and rg.shares_rates else lookup_corners(ps.sfm, ps.ef, frames, turn)
    assert c_i is not None
    if ps.compiled:
        t = ps.table
        sums = epoch_sums(t.flat, t.width, c_i.rows, c_i.weights, c_i.bad, n_t, ps.yn_tiled)
        e_r = None
        if rg is not None and c_r is not None:
            e_r = _ranging_compiled(rg, c_r, n_t, n_k, n_b)
    else:
        sums, e_r = _numpy_sums(ps, c_i, c_r, n_ax)
    s = sums.astype(float).reshape(3, n_ax, n_k, n_b).transpose(0, 1, 3, 2)
    return misfit_from_sums(s[0], s[1], s[2], ps.yy, n_t), e_r


def _numpy_sums(ps: _Pass, c_i: Corners, c_r: Corners | None, n_ax: int) -> tuple[F32, F64 | None]:
    """``sum p``, ``sum p^2``, ``sum p y`` (3, A, K B) and the ranging term (A, K) or None of
    a chunk, with numpy in blocks of ``ps.block_axes`` (module docstring)."""
    n_t, n_b, n_k = ps.yn_tiled.shape[0], ps.n_b, ps.sfm.n_phases
    rg = ps.ranging
    sums = np.empty((3, n_ax, n_k * n_b), dtype=np.float32)  # sum p, p^2, p y over epochs
    e_r = None if rg is None else np.empty((n_ax, n_k))
    for a0 in range(0, n_ax, ps.block_axes):
        a1 = min(a0 + ps.block_axes, n_ax)
        sl = slice(a0 * n_t, a1 * n_t)
        p = gather(ps.table.windows, c_i, sl).reshape(a1 - a0, n_t, n_k * n_b)
        np.add.reduce(p, axis=1, out=sums[0, a0:a1])
        np.einsum("ntj,ntj->nj", p, p, out=sums[1, a0:a1])
        np.einsum("ntj,tj->nj", p, ps.yn_tiled, out=sums[2, a0:a1])
        if rg is not None and e_r is not None and c_r is not None:
            e_r[a0:a1] = _ranging_block(rg, c_r, sl, n_t, n_k, n_b)
    return sums, e_r


def _ranging_block(rg: _Ranging, corners: Corners, sl: slice, n_t: int, n_k: int, n_b: int) -> F64:
    """The ranging term (n, K) of a block: ``sum (o - o_meas)^2 / norm`` over the measured
    epochs and bands (offset 0, the centre of mass, where there is no phase vector)."""
    d = gather(rg.offsets.windows, corners, sl, fill=0.0).reshape(-1, n_t, n_k * n_b)
    n_ax = d.shape[0]
    if rg.norm <= 0:
        return np.zeros((n_ax, n_k))
    d -= rg.meas_tiled
    if rg.ok_tiled is not None:
        d *= rg.ok_tiled
    e = np.einsum("ntj,ntj->nj", d, d).reshape(n_ax, n_k, n_b)
    return np.asarray(e.sum(axis=-1), dtype=float) / rg.norm


def _ranging_compiled(rg: _Ranging, corners: Corners, n_t: int, n_k: int, n_b: int) -> F64:
    """The ranging term (A, K) of a chunk by the compiled loop (as :func:`_ranging_block`)."""
    n_ax = corners.rows.shape[0] // n_t
    if rg.norm <= 0:
        return np.zeros((n_ax, n_k))
    t = rg.offsets
    ok = np.ones_like(rg.meas_tiled) if rg.ok_tiled is None else rg.ok_tiled
    d2 = epoch_sums(t.flat, t.width, corners.rows, corners.weights, corners.bad, n_t,
                    rg.meas_tiled, ok, fill=0.0)  # fmt: skip
    return np.asarray(d2[0].reshape(n_ax, n_k, n_b).sum(axis=-1), dtype=float) / rg.norm
