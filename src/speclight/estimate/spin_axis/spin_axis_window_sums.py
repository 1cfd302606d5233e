"""The epoch sums of the spin-axis grid pass in one compiled loop (numba, where installed).

:mod:`.spin_axis_grid` computes, for a chunk of axes, sums over the epochs of interpolated
windows of the spin-frame table. With numpy that takes a gathered copy of every corner
window (``table[rows]``), the corners weighed into a block of windows (``matmul``), then one
pass over the block per sum: the 11.5 kB of corner windows of a passive lookup are written
once and read twice more, and the block's windows three times. Here one loop per axis reads
each corner window straight from the table, adds the corners with their weights in
registers and adds the products to the axis's sums (3 windows, in the first-level cache),
two epochs per pass over the window: the table is read once per lookup corner and nothing
else leaves the cache. The same arithmetic in the same order (the corners in order, then
the epochs in order, float32): the sums equal the numpy blocks' to float32 rounding (the
weighing by ``matmul`` may round differently; with one corner they are bitwise the same).

numba is an optional dependency (``pip install 'speclight[fast]'``); without it
:func:`compiled_available` is False and the grid pass uses its numpy blocks. The loop is
compiled on first use (a few seconds) and then loaded from numba's cache on disk; it releases
the GIL, so the grid pass's threads (``workers``) run it in parallel.
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
    """Sums over the ``n_t`` epochs (even) of each axis into ``out`` (S, A, J).

    Lookup ``i = a n_t + t`` (axis ``a``, epoch ``t``) is the window ``p`` of ``J`` floats
    ``sum_c weights[i, c] flat[rows[i, c] width : rows[i, c] width + J]`` over its 4 corners
    (added in order; only the first where ``rows`` has one column). With ``S = 3``:
    ``out[:, a] = sum_t p, sum_t p^2, sum_t p y[t]``; with ``S = 1``: ``out[0, a] =
    sum_t ((p - y[t]) ok[t])^2``. Two epochs per pass over the window: each sum is loaded
    and stored once per pair and added to in epoch order (``(s + v_t) + v_t+1``, as one
    epoch at a time would).
    """
    n_sums, n_ax, n_j = out.shape
    k = 3 if rows.shape[1] == 4 else 0  # one corner: q1..q3 are q0 and never read
    k1, k2 = min(1, k), min(2, k)
    last_ok = ok.shape[0] - 1
    s1 = np.empty(n_j, np.float32)
    s2 = np.empty(n_j, np.float32)
    sy = np.empty(n_j, np.float32)
    for a in range(n_ax):
        s1[:] = 0.0
        s2[:] = 0.0
        sy[:] = 0.0
        for t in range(0, n_t, 2):
            i, h = a * n_t + t, a * n_t + t + 1  # the pair's lookups
            # slices: unit stride and no index wrap-around, so the loop below vectorises
            q0 = flat[rows[i, 0] * width : rows[i, 0] * width + n_j]
            q1 = flat[rows[i, k1] * width : rows[i, k1] * width + n_j]
            q2 = flat[rows[i, k2] * width : rows[i, k2] * width + n_j]
            q3 = flat[rows[i, k] * width : rows[i, k] * width + n_j]
            r0 = flat[rows[h, 0] * width : rows[h, 0] * width + n_j]
            r1 = flat[rows[h, k1] * width : rows[h, k1] * width + n_j]
            r2 = flat[rows[h, k2] * width : rows[h, k2] * width + n_j]
            r3 = flat[rows[h, k] * width : rows[h, k] * width + n_j]
            w0, w1, w2, w3 = weights[i, 0], weights[i, k1], weights[i, k2], weights[i, k]
            u0, u1, u2, u3 = weights[h, 0], weights[h, k1], weights[h, k2], weights[h, k]
            yt, yu = y[t], y[t + 1]
            okt, oku = ok[min(t, last_ok)], ok[min(t + 1, last_ok)]
            for j in range(n_j):  # the branches are the same for every j: hoisted by LLVM
                v = w0 * q0[j]
                x = u0 * r0[j]
                if k == 3:
                    v += w1 * q1[j]
                    x += u1 * r1[j]
                    v += w2 * q2[j]
                    x += u2 * r2[j]
                    v += w3 * q3[j]
                    x += u3 * r3[j]
                if n_sums == 3:
                    s1[j] = s1[j] + v + x
                    s2[j] = s2[j] + v * v + x * x
                    sy[j] = sy[j] + v * yt[j] + x * yu[j]
                else:
                    d = (v - yt[j]) * okt[j]
                    e = (x - yu[j]) * oku[j]
                    s2[j] = s2[j] + d * d + e * e
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
    lookup has the weights (``fill``, 0, ...) for a NaN window or zeros for a zero one; it
    takes the epochs in pairs: an odd ``T`` is padded with a copy of the last epoch's corners
    at weight 0 (and ``y``, ``ok`` 0). All exact on a finite table (``v + 0 x = v``,
    ``0 x = 0``; a padded window is one the lookup already reads, so a NaN cell there makes
    the sums NaN either way): the windows and sums are those of :func:`.spin_axis_grid.gather`
    and the numpy blocks, to float32 rounding.

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
    n_ax, n_even = n_look // n_t, n_t + n_t % 2
    n_pad = 1 if n_c == 1 else 4
    rows4 = np.empty((n_ax, n_even, n_pad), np.int64)
    rows4[:, :n_t] = rows[:, :1].reshape(n_ax, n_t, 1)
    rows4[:, :n_t, :n_c] = rows.reshape(n_ax, n_t, n_c)
    rows4[:, n_t:] = rows4[:, n_t - 1 : n_t]  # odd T: an epoch of weight 0 (adds 0)
    w4 = np.zeros((n_ax, n_even, n_pad), np.float32)
    w4[:, :n_t, :n_c] = 1.0 if weights is None else weights.reshape(n_ax, n_t, n_c)
    w_bad = w4[:, :n_t].reshape(n_look, n_pad)  # a view
    w_bad[bad] = 0.0
    w_bad[bad, 0] = fill
    y_even = np.zeros((n_even, y.shape[1]), np.float32)
    y_even[:n_t] = y
    ok_even = np.ones((1, 1), np.float32)
    if ok is not None:
        ok_even = np.zeros((n_even, ok.shape[1]), np.float32)
        ok_even[:n_t] = ok
    out = np.empty((3 if ok is None else 1, n_ax, y.shape[1]), np.float32)
    _compiled()(
        flat,
        int(width),
        rows4.reshape(n_ax * n_even, n_pad),
        w4.reshape(n_ax * n_even, n_pad),
        n_even,
        y_even,
        ok_even,
        out,
    )
    return out
