"""Solar spectral irradiance at the target from the ASTM E490-00a air-mass-zero spectrum.

The table is ASTM E490-00a(2019), "Standard Solar Constant and Zero Air Mass Solar Spectral
Irradiance Tables" (ASTM International), shipped as ``data/solar/astm_e490_00a_am0.csv``
(see ``data/solar/PROVENANCE.md``). Its integral is 1366.1 W m-2 at 1 AU.
"""

from __future__ import annotations

from functools import lru_cache
from importlib import resources

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.constants import AU_M, SUN_RADIUS_M
from speclight.errors import InputError
from speclight.wavelength_grid import bin_bounds_nm, cumulative_integral

#: Mean angular radius of the solar disk seen from 1 AU [rad] (959.63 arcsec): the nominal
#: solar radius over 1 au (:mod:`speclight.constants`), the ratio taken in km.
SOLAR_ANGULAR_RADIUS_RAD = float(np.arcsin((SUN_RADIUS_M / 1e3) / (AU_M / 1e3)))


@lru_cache(maxsize=1)
def solar_table() -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return the ASTM E490-00a table (wavelength [nm], irradiance at 1 AU [W m-2 nm-1]).

    Source: ASTM E490-00a(2019) via aphalo/photobiologySun; see ``data/solar/PROVENANCE.md``.
    """
    text = (
        resources.files("speclight").joinpath("data", "solar", "astm_e490_00a_am0.csv").read_text()
    )
    data = np.loadtxt(text.splitlines(), delimiter=",", comments="#", skiprows=3)
    return data[:, 0].copy(), data[:, 1].copy()


def solar_irradiance_W_m2_nm(
    wavelength_nm: ArrayLike,
    distance_au: ArrayLike = 1.0,
    bin_width_nm: ArrayLike | None = None,
) -> NDArray[np.float64]:
    """Solar spectral irradiance at the target, averaged over each wavelength bin.

    Parameters
    ----------
    wavelength_nm
        Bin centres (L,) [nm], strictly increasing.
    distance_au
        Sun-target distance [au], a number or an (N,) array.
    bin_width_nm
        Bin widths [nm] (a number or (L,)); default: edges half-way between centres.

    Returns
    -------
    numpy.ndarray
        (L,) for a scalar distance or (N, L) [W m-2 nm-1]: the mean of the ASTM E490-00a
        spectrum (linearly interpolated) over each bin, times ``1 / distance_au**2``. The bin
        average conserves the integral: ``sum(E * width)`` equals the table's integral over the
        bins.

    References
    ----------
    ASTM E490-00a(2019), Standard Solar Constant and Zero Air Mass Solar Spectral Irradiance
    Tables, ASTM International, doi:10.1520/E0490-00AR19.
    """
    wl = np.atleast_1d(np.asarray(wavelength_nm, dtype=float))
    if wl.ndim != 1 or (wl.size > 1 and np.any(np.diff(wl) <= 0)):
        raise InputError(
            "wavelength_nm must be a strictly increasing 1-D array of bin centres",
            field="wavelength_nm",
        )
    table_wl, table_e = solar_table()
    lo, hi = bin_bounds_nm(wl, bin_width_nm)
    if lo[0] < table_wl[0] or hi[-1] > table_wl[-1]:
        raise InputError(
            f"wavelength bins {lo[0]:g}-{hi[-1]:g} nm leave the ASTM E490 table "
            f"({table_wl[0]:g}-{table_wl[-1]:g} nm); choose a grid inside it",
            field="wavelength_nm",
        )
    cum_hi = cumulative_integral(table_wl, table_e, hi)
    mean = (cum_hi - cumulative_integral(table_wl, table_e, lo)) / (hi - lo)
    d = np.asarray(distance_au, dtype=float)
    if np.any(~(d > 0) & np.isfinite(d)):
        raise InputError(f"distance_au must be > 0, got {distance_au!r}", field="distance_au")
    if d.ndim == 0:
        return mean / float(d) ** 2
    return mean[None, :] / d.reshape(-1, 1) ** 2
