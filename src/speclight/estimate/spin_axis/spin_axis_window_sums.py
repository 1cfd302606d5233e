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
    flat: F32,
    width: int,
    rows: I64,
    weights: F32,
    bad: BOOL,
    fill: float,
    n_t: int,
    y: F32,
    ok: F32,
    out: F32,
) -> None:  # pragma: no cover - run compiled by numba (tests call it through the grid pass)
    """Sums over the ``n_t`` epochs of each axis into ``out`` (S, A, J).

    Lookup ``i = a n_t + t`` (axis ``a``, epoch ``t``) is the window ``p`` of ``J`` floats
    ``sum_c weights[i, c] flat[rows[i, c] width : rows[i, c] width + J]`` (``fill`` where
    ``bad[i]``). With ``S = 3``: ``out[:, a] = sum_t p, sum_t p^2, sum_t p y[t]``; with
    ``S = 1``: ``out[0, a] = sum_t ((p - y[t]) ok[t])^2``.
    """
    n_sums, n_ax, n_j = out.shape
    n_c = rows.shape[1]
    p = np.empty(n_j, np.float32)
    s1 = np.empty(n_j, np.float32)
    s2 = np.empty(n_j, np.float32)
    sy = np.empty(n_j, np.float32)
    for a in range(n_ax):
        s1[:] = 0.0
        s2[:] = 0.0
        sy[:] = 0.0
        for t in range(n_t):
            i = a * n_t + t
            o = rows[i, 0] * width
            w = weights[i, 0]
            src = flat[o : o + n_j]  # a slice: unit stride, no index wrap-around (vectorised)
            for j in range(n_j):
                p[j] = w * src[j]
            for c in range(1, n_c):
                o = rows[i, c] * width
                w = weights[i, c]
                src = flat[o : o + n_j]
                for j in range(n_j):
                    p[j] += w * src[j]
            if bad[i]:
                p[:] = fill
            yt = y[t]
            if n_sums == 3:
                for j in range(n_j):
                    v = p[j]
                    s1[j] += v
                    s2[j] += v * v
                    sy[j] += v * yt[j]
            else:
                okt = ok[t]
                for j in range(n_j):
                    d = (p[j] - yt[j]) * okt[j]
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

    Parameters
    ----------
    flat
        The table, contiguous float32, cell ``r`` at ``flat[r width : (r + 1) width]``.
    width
        Floats per cell (the table's channels).
    rows
        First cell of each corner window (A T, corners), axis slowest.
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
        The window of a bad lookup.

    Returns
    -------
    The sums (S, A, J) float32.
    """
    n_ax = rows.shape[0] // n_t
    w = np.ones(rows.shape, np.float32) if weights is None else weights
    out = np.empty((3 if ok is None else 1, n_ax, y.shape[1]), np.float32)
    ok_arr = np.ones((1, 1), np.float32) if ok is None else ok
    _compiled()(
        flat,
        int(width),
        np.ascontiguousarray(rows, dtype=np.int64),
        np.ascontiguousarray(w, dtype=np.float32),
        np.ascontiguousarray(bad),
        float(fill),
        int(n_t),
        np.ascontiguousarray(y, dtype=np.float32),
        np.ascontiguousarray(ok_arr, dtype=np.float32),
        out,
    )
    return out
