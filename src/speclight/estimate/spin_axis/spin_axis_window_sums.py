"""The epoch sums of the spin-axis grid pass in one compiled loop (numba, where installed).

:mod:`.spin_axis_grid` computes, for a chunk of axes, sums over the epochs of interpolated
windows of the spin-frame table. With numpy that takes a gathered copy of every corner
window (``table[rows]``), the corners weighed into a block of windows (``matmul``), then one
pass over the block per sum: the 11.5 kB of corner windows of a passive lookup are written
once and read twice more, and the block's windows three times. Here one loop per axis reads
each corner window straight from the table into one window-sized buffer (the weighed sum of
the corners) and adds its products to the axis's sums, which stay in the first-level cache:
the table is read once per lookup corner and nothing else leaves the cache. The same
arithmetic in the same order (the corners in order, then the epochs in order, float32):
the sums equal numpy's to float32 rounding (fused multiply-adds may round differently).

numba is an optional dependency (``pip install 'speclight[fast]'``); without it
:func:`compiled_available` is False and the grid pass uses its numpy blocks. The loop is
compiled on first use (about a second) and cached on disk by numba; it releases the GIL, so
the grid pass's threads (``workers``) run it in parallel.
"""

from __future__ import annotations

from functools import cache
from typing import Any

import numpy as np
from numpy.typing import NDArray

F32 = NDArray[np.float32]
I64 = NDArray[np.int64]
BOOL = NDArray[np.bool_]


@cache
def compiled_available() -> bool:
    """True where numba imports (the compiled loop can be used)."""
    try:
        import numba  # noqa: F401
    except ImportError:
        return False
    return True


def _epoch_sums_loop(
    flat: F32, width: int, rows: I64, weights: F32, n_t: int, y: F32, ok: F32, out: F32
) -> None:  # pragma: no cover - run compiled by numba (tests call it through the grid pass)
    """Sums over the ``n_t`` epochs of each axis into ``out`` (S, A, J).

    Lookup ``i = a n_t + t`` (axis ``a``, epoch ``t``) is the window ``p`` of ``J`` floats
    ``sum_c weights[i, c] flat[rows[i, c] width : rows[i, c] width + J]`` over its 4 corners
    (added in order; only the first where ``rows`` has one column). With ``S = 3``:
    ``out[:, a] = sum_t p, sum_t p^2, sum_t p y[t]``; with ``S = 1``: ``out[0, a] =
    sum_t ((p - y[t]) ok[t])^2``.
    """
    n_sums, n_ax, n_j = out.shape
    four = rows.shape[1] == 4
    s1 = np.empty(n_j, np.float32)
    s2 = np.empty(n_j, np.float32)
    sy = np.empty(n_j, np.float32)
    for a in range(n_ax):
        s1[:] = 0.0
        s2[:] = 0.0
        sy[:] = 0.0
        for t in range(n_t):
            i = a * n_t + t
            # slices: unit stride and no index wrap-around, so the loops below vectorise
            k = 3 if four else 0  # one corner: q1..q3 are q0, never read
            q0 = flat[rows[i, 0] * width : rows[i, 0] * width + n_j]
            q1 = flat[rows[i, min(1, k)] * width : rows[i, min(1, k)] * width + n_j]
            q2 = flat[rows[i, min(2, k)] * width : rows[i, min(2, k)] * width + n_j]
            q3 = flat[rows[i, k] * width : rows[i, k] * width + n_j]
            w0, w1, w2, w3 = (
                weights[i, 0],
                weights[i, min(1, k)],
                weights[i, min(2, k)],
                weights[i, k],
            )
            yt = y[t]
            okt = ok[min(t, ok.shape[0] - 1)]
            for j in range(n_j):  # the branches are the same for every j: hoisted by LLVM
                v = w0 * q0[j]
                if four:
                    v += w1 * q1[j]
                    v += w2 * q2[j]
                    v += w3 * q3[j]
                if n_sums == 3:
                    s1[j] += v
                    s2[j] += v * v
                    sy[j] += v * yt[j]
                else:
                    d = (v - yt[j]) * okt[j]
                    s2[j] += d * d
        if n_sums == 3:
            out[0, a] = s1
            out[1, a] = s2
            out[2, a] = sy
        else:
            out[0, a] = s2


@cache
def _compiled() -> Any:
    """:func:`_epoch_sums_loop` compiled by numba (no bounds checks, numpy's float rules)."""
    import numba

    return numba.njit(cache=True, nogil=True, boundscheck=False, error_model="numpy")(
        _epoch_sums_loop
    )


def epoch_sums(
    flat: F32,
    width: int,
    rows: I64,
    weights: F32 | None,
    bad: BOOL,
    n_t: int,
    y: F32,
    ok: F32 | None = None,
    fill: float = np.nan,
) -> F32:
    """Sums over the epochs of interpolated windows of ``flat``, compiled (module docstring).

    The loop adds 1 or 4 corners: 2 are padded with the first corner at weight 0, and a bad
    lookup has the weights (``fill``, 0, ...) for a NaN window or zeros for a zero one. On a
    finite table both are exact (``v + 0 x = v``, ``0 x = 0``), so the windows are those of
    :func:`.spin_axis_grid.gather`.

    Parameters
    ----------
    flat
        The table, contiguous float32, cell ``r`` at ``flat[r width : (r + 1) width]``.
    width
        Floats per cell (the table's channels).
    rows
        First cell of each corner window (A T, corners <= 4), axis slowest.
    weights
        Corner weights (A T, corners) float32, or None for one corner of weight 1.
    bad
        Lookups without a geometry (A T,): their window is ``fill``.
    n_t
        Epochs ``T`` per axis.
    y
        (T, J): the mean-normalised curves (intensity sums), or the measured values the
        windows are compared with (``ok`` given).
    ok
        None: return ``sum p``, ``sum p^2``, ``sum p y`` (3, A, J); else the weights (T, J)
        of ``sum ((p - y) ok)^2`` (1, A, J).
    fill
        The window of a bad lookup: NaN or 0.

    Returns
    -------
    The sums (S, A, J) float32.
    """
    if not (np.isnan(fill) or fill == 0.0):
        raise ValueError(f"fill = {fill} must be NaN or 0 (the window of a bad lookup)")
    n_look, n_c = rows.shape
    n_pad = 1 if n_c == 1 else 4
    rows4 = np.repeat(rows[:, :1], n_pad, axis=1)
    rows4[:, :n_c] = rows
    w4 = np.zeros((n_look, n_pad), np.float32)
    w4[:, :n_c] = 1.0 if weights is None else weights
    w4[bad] = 0.0
    w4[bad, 0] = fill
    out = np.empty((3 if ok is None else 1, n_look // n_t, y.shape[1]), np.float32)
    ok_arr = np.ones((1, 1), np.float32) if ok is None else ok
    _compiled()(
        flat,
        int(width),
        rows4,
        w4,
        int(n_t),
        np.ascontiguousarray(y, dtype=np.float32),
        np.ascontiguousarray(ok_arr, dtype=np.float32),
        out,
    )
    return out
