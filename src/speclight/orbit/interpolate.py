"""Lagrange interpolation of tabulated vectors (ephemerides, slowly varying matrices).

One helper serves the CPF reader, the tabulated-ephemeris reader and the fast Earth
orientation path: a sliding-window Lagrange polynomial of degree ``n_points - 1``
centred on each query epoch.

Why Lagrange of degree 9 (10 points): it is what the ILRS recommends for CPF files
("the CPF files with many records per day are interpolated with a high order (9th)
polynomial", Ricklefs et al., *Consolidated Laser Ranging Prediction Format, Version
2.00*, ILRS 2018), it needs positions only (CPF velocity records are optional), and for
a circular orbit sampled at step ``h`` its error scales as ``r (n h)^10 / 10!`` with
``n`` the mean motion; for LEO to MEO at the usual 60 s to 240 s steps that is far
below a millimetre. ``tests/orbit/test_orbit_cpf.py`` measures it against SGP4.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

DEFAULT_POINTS = 10


def lagrange_interpolate(
    x_nodes: ArrayLike,
    y_nodes: ArrayLike,
    x: ArrayLike,
    n_points: int = DEFAULT_POINTS,
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Interpolate tabulated values with a sliding Lagrange polynomial.

    Parameters
    ----------
    x_nodes
        Abscissae of the table, strictly increasing, shape (M,).
    y_nodes
        Tabulated values, shape (M,) or (M, K).
    x
        Query abscissae, shape (N,).
    n_points
        Points per window (polynomial degree + 1); reduced to M for short tables. The
        window is centred on the query and shifted inwards at the ends of the table.

    Returns
    -------
    y : ndarray
        Interpolated values, shape (N,) or (N, K); NaN outside ``[x_nodes[0],
        x_nodes[-1]]`` (no extrapolation) and for non-finite queries.
    ok : ndarray of bool
        Shape (N,): True where ``y`` is valid.
    """
    xn = np.asarray(x_nodes, dtype=np.float64)
    yn = np.asarray(y_nodes, dtype=np.float64)
    xq = np.atleast_1d(np.asarray(x, dtype=np.float64))
    squeeze = yn.ndim == 1
    if squeeze:
        yn = yn[:, None]
    m = xn.shape[0]
    if m < 2 or yn.shape[0] != m:
        raise ValueError(f"need at least 2 nodes with matching values, got {m} and {yn.shape}")
    n = min(int(n_points), m)
    ok, idx, _, weights, _ = lagrange_window(xn, xq, n)
    y = np.zeros((xq.shape[0], yn.shape[1]))
    for j in range(n):
        y += weights[:, j, None] * yn[idx[:, j]]
    y[~ok] = np.nan
    return (y[:, 0] if squeeze else y), ok


F64 = NDArray[np.float64]


def lagrange_window(
    xn: F64, xq: F64, n: int
) -> tuple[NDArray[np.bool_], NDArray[np.intp], F64, F64, F64]:
    """The sliding window of ``n`` nodes centred on each query and its Lagrange basis.

    Returns ``(ok, idx, dx, basis, slope)``: ``ok`` (N,) the queries inside the nodes' span
    (finite); ``idx`` (N, n) the window's node indices (shifted inwards at the table's ends);
    ``dx`` (N, n) ``x - x_k``; ``basis`` (N, n) ``L_j(x)``; ``slope`` (N, n) ``L_j'(x_j) =
    sum_{k != j} 1 / (x_j - x_k)`` (for Hermite interpolation). The numerator
    ``prod_{k != j} (x - x_k)`` comes from prefix and suffix products (no division, so exact
    at the nodes); the denominators depend only on the window's start.
    """
    m = xn.size
    ok = np.isfinite(xq) & (xq >= xn[0]) & (xq <= xn[-1])
    xs = np.where(ok, xq, xn[0])
    start = np.clip(np.searchsorted(xn, xs) - n // 2, 0, m - n)
    idx = start[:, None] + np.arange(n)  # (N, n)
    dx = xs[:, None] - xn[idx]  # (N, n)
    left = np.ones_like(dx)
    right = np.ones_like(dx)
    left[:, 1:] = np.cumprod(dx[:, :-1], axis=1)
    right[:, :-1] = np.cumprod(dx[:, :0:-1], axis=1)[:, ::-1]
    starts, inverse = np.unique(start, return_inverse=True)
    xw = xn[starts[:, None] + np.arange(n)]  # (S, n)
    eye = np.eye(n, dtype=bool)
    diff = np.where(eye, 1.0, xw[:, :, None] - xw[:, None, :])  # (S, n, n)
    inv = inverse.reshape(-1)
    basis = left * right / diff.prod(axis=2)[inv]
    slope = np.where(eye, 0.0, 1.0 / diff).sum(axis=2)[inv]
    return ok, idx, dx, basis, slope
