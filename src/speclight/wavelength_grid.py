"""The wavelength grid as bins: edges, widths, and exact bin averages of tabulated curves.

speclight treats each wavelength sample as the mean over its bin, whose edges lie half-way
between neighbouring samples (the outer bins extend half a step outward). Integrals over
wavelength are bin sums, and tabulated curves are put on the grid by averaging their
piecewise-linear interpolant exactly over each bin, so no narrow feature is missed or
counted twice. Every stage (illumination, render, atmosphere, instrument, ranging) uses
these helpers; nothing else computes bin edges or integrates a table.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError


def check_wavelength_grid(wavelength_nm: ArrayLike) -> NDArray[np.float64]:
    """Return the grid as a float array after checking it is 1-D, positive and increasing.

    Raises
    ------
    InputError
        If not (field ``spectrum``).
    """
    wl = np.asarray(wavelength_nm, dtype=np.float64)
    if wl.ndim != 1 or wl.size < 2 or not np.all(np.isfinite(wl)) or np.any(wl <= 0):
        raise InputError(
            f"wavelength grid must be a 1-D array of at least 2 positive finite values in nm, "
            f"got shape {wl.shape}",
            field="spectrum",
        )
    if np.any(np.diff(wl) <= 0):
        raise InputError("wavelength grid must be strictly increasing", field="spectrum")
    return wl


def grid_from_range_nm(min_nm: float, max_nm: float, step_nm: float) -> NDArray[np.float64]:
    """Bin centres from ``min_nm`` to ``max_nm`` (included when on the grid) in ``step_nm`` [nm]."""
    n = int(np.floor((max_nm - min_nm) / step_nm + 1e-9)) + 1
    return np.asarray(min_nm + step_nm * np.arange(n), dtype=np.float64)


def bin_edges_nm(wavelength_nm: ArrayLike) -> NDArray[np.float64]:
    """Bin edges [nm] (L+1,): mid-points between samples, outer bins symmetric."""
    wl = check_wavelength_grid(wavelength_nm)
    mid = 0.5 * (wl[1:] + wl[:-1])
    return np.concatenate(([wl[0] - (mid[0] - wl[0])], mid, [wl[-1] + (wl[-1] - mid[-1])]))


def bin_widths_nm(wavelength_nm: ArrayLike) -> NDArray[np.float64]:
    """Bin widths [nm] (L,), the quadrature weights of every wavelength integral."""
    return np.diff(bin_edges_nm(wavelength_nm))


def bin_bounds_nm(
    wavelength_nm: ArrayLike, bin_width_nm: ArrayLike | None = None
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Lower and upper edges [nm] (L,) and (L,) of the bins centred on ``wavelength_nm``.

    Without ``bin_width_nm`` these are :func:`bin_edges_nm` (half-way between neighbouring
    centres, the outer bins symmetric about their centre); a single centre then needs an
    explicit width. With it, each bin is ``centre -+ width / 2``.
    """
    wl = np.asarray(wavelength_nm, dtype=float)
    if bin_width_nm is not None:
        width = np.broadcast_to(np.asarray(bin_width_nm, dtype=float), wl.shape)
        if np.any(~(width > 0)):
            raise InputError(f"bin_width_nm = {bin_width_nm!r} must be > 0", field="bin_width_nm")
        return wl - 0.5 * width, wl + 0.5 * width
    if wl.size < 2:
        raise InputError(
            "a single wavelength needs an explicit bin_width_nm > 0", field="bin_width_nm"
        )
    mid = 0.5 * (wl[1:] + wl[:-1])
    lo = np.concatenate([[wl[0] - (mid[0] - wl[0])], mid])
    hi = np.concatenate([mid, [wl[-1] + (wl[-1] - mid[-1])]])
    return lo, hi


#: Width given to a grid of a single wavelength [nm] (it is rendered as a 1 nm wide bin).
SINGLE_BIN_WIDTH_NM = 1.0


def grid_bin_bounds_nm(
    wavelength_nm: ArrayLike,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """:func:`bin_bounds_nm` of a render grid: a single wavelength is a
    :data:`SINGLE_BIN_WIDTH_NM` wide bin."""
    wl = np.asarray(wavelength_nm, dtype=float).ravel()
    return bin_bounds_nm(wl, SINGLE_BIN_WIDTH_NM if wl.size == 1 else None)


def cumulative_integral(
    x: NDArray[np.float64], y: NDArray[np.float64], at: ArrayLike
) -> NDArray[np.float64]:
    """Exact integral of the piecewise-linear (x, y) from x[0] to ``at``.

    ``y`` may have leading axes (..., n). ``at`` is clipped to the table (the curve is 0 to
    the left and the integral constant to the right of it).
    """
    seg = 0.5 * (y[..., 1:] + y[..., :-1]) * np.diff(x)
    cum = np.concatenate((np.zeros((*y.shape[:-1], 1)), np.cumsum(seg, axis=-1)), axis=-1)
    a = np.clip(at, x[0], x[-1])
    k = np.clip(np.searchsorted(x, a, side="right") - 1, 0, x.size - 2)
    dx = a - x[k]
    slope = (y[..., k + 1] - y[..., k]) / (x[k + 1] - x[k])
    return cum[..., k] + y[..., k] * dx + 0.5 * slope * dx**2


def bin_average(
    x_nm: ArrayLike,
    y: ArrayLike,
    wavelength_nm: ArrayLike,
    outside: Literal["zero", "edge"] = "zero",
) -> NDArray[np.float64]:
    """Average of a piecewise-linear curve over every bin of the wavelength grid.

    Parameters
    ----------
    x_nm
        Abscissae of the table [nm] (n,), strictly increasing.
    y
        Values (..., n); leading axes are kept (e.g. one curve per epoch).
    wavelength_nm
        The grid (L,).
    outside
        ``zero``: the curve is 0 beyond the table; ``edge``: it keeps its end values.

    Returns
    -------
    numpy.ndarray
        Bin averages (..., L).
    """
    x = np.asarray(x_nm, dtype=np.float64)
    yy = np.asarray(y, dtype=np.float64)
    edges = bin_edges_nm(wavelength_nm)
    if outside == "edge":
        lo, hi = min(edges[0], x[0]) - 1.0, max(edges[-1], x[-1]) + 1.0
        x = np.concatenate(([lo], x, [hi]))
        yy = np.concatenate((yy[..., :1], yy, yy[..., -1:]), axis=-1)
    cum = cumulative_integral(x, yy, edges)
    return np.diff(cum, axis=-1) / np.diff(edges)
