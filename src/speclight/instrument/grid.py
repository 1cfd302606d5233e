"""The wavelength grid as bins: edges, widths, and exact bin averages of tabulated curves.

speclight treats each wavelength sample as the mean over its bin, whose edges lie half-way
between neighbouring samples (the outer bins extend half a step outward). Integrals over
wavelength are bin sums, and tabulated curves are put on the grid by averaging their
piecewise-linear interpolant exactly over each bin, so no narrow feature is missed or
counted twice. The atmosphere models use the same helpers.
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


def bin_edges_nm(wavelength_nm: ArrayLike) -> NDArray[np.float64]:
    """Bin edges [nm] (L+1,): mid-points between samples, outer bins symmetric."""
    wl = check_wavelength_grid(wavelength_nm)
    mid = 0.5 * (wl[1:] + wl[:-1])
    return np.concatenate(([wl[0] - (mid[0] - wl[0])], mid, [wl[-1] + (wl[-1] - mid[-1])]))


def bin_widths_nm(wavelength_nm: ArrayLike) -> NDArray[np.float64]:
    """Bin widths [nm] (L,), the quadrature weights of every wavelength integral."""
    return np.diff(bin_edges_nm(wavelength_nm))


def _cumulative(x: NDArray[np.float64], y: NDArray[np.float64], at: NDArray[np.float64]) -> NDArray:
    """Integral of the piecewise-linear (x, y) from x[0] to ``at`` (0 outside on the left)."""
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
    cum = _cumulative(x, yy, edges)
    return np.diff(cum, axis=-1) / np.diff(edges)
