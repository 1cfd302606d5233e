"""Magnitudes beyond AB at the aperture: range-normalised ("standard") and Vega V.

The exo-atmospheric AB magnitude is :func:`~speclight.instrument.photometry.ab_magnitude` of
the irradiance without the atmosphere's transmission (the pipeline passes it the intensity
over range squared); this module adds the two conventions SSA catalogues use:

* the standard magnitude, moved to a range of 1000 km by the inverse-square law,
  ``m_std = m - 5 log10(range / 1000 km)`` (the phase angle is not normalised: that needs a
  phase law, which is what the simulation is for);
* the Vega magnitude in the Johnson-Cousins V band, Bessell's realisation (speclite's
  ``bessell-V``): the AB magnitude in that band minus ``V_AB - V_Vega = 0.02`` (Blanton &
  Roweis 2007, AJ 133, 734, table 1). No Vega spectrum ships with the installed packages, so
  the zero point is this published offset rather than synthetic photometry of a Vega
  spectrum (e.g. CALSPEC ``alpha_lyr_stis``); V zero points of different realisations
  differ by about 0.01-0.02 mag (Bessell 2005, ARA&A 43, 293), which bounds its accuracy.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError
from speclight.instrument.bands import band_response, filter_band
from speclight.instrument.photometry import ab_magnitude
from speclight.wavelength_grid import check_wavelength_grid

#: Range of the standard magnitude [m]: 1000 km.
STANDARD_RANGE_M = 1.0e6
#: V_AB - V_Vega of the Bessell V band [mag] (Blanton & Roweis 2007, AJ 133, 734, table 1).
V_AB_MINUS_VEGA = 0.02
#: speclite's name of the V band.
V_FILTER = "bessell-V"


def standard_magnitude(
    magnitude: ArrayLike, range_m: ArrayLike, reference_range_m: float = STANDARD_RANGE_M
) -> NDArray[np.float64]:
    """A magnitude moved to ``reference_range_m`` by the inverse-square law.

    .. math:: m_{std} = m - 5 \\log_{10}(r / r_0),\\quad r_0 = 1000\\,\\mathrm{km}

    Parameters
    ----------
    magnitude
        (N,) or (N, B) magnitudes [mag].
    range_m
        (N,) observer-target distance [m].
    reference_range_m
        Range the magnitude is moved to [m]; 1000 km by default.

    Returns
    -------
    numpy.ndarray
        Same shape as ``magnitude`` [mag]; NaN where the magnitude or range is NaN.
    """
    if not (np.isfinite(reference_range_m) and reference_range_m > 0):
        raise InputError(f"reference range {reference_range_m!r} m must be > 0", field="range_m")
    mag = np.asarray(magnitude, dtype=np.float64)
    r = np.asarray(range_m, dtype=np.float64)
    if mag.ndim == 2:
        r = r[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.asarray(mag - 5.0 * np.log10(r / reference_range_m))


def v_band_response(wavelength_nm: ArrayLike) -> NDArray[np.float64] | None:
    """speclite's ``bessell-V`` on the grid (1, L), or ``None`` if the grid misses the band.

    The band counts as covered when
    :data:`~speclight.instrument.bands.MIN_FRACTION_ON_GRID` of its response is on the grid,
    as for a scenario's bands.
    """
    wl = check_wavelength_grid(wavelength_nm)
    try:  # the name is speclite's own: the one error left is a grid that misses the band
        return band_response([filter_band(V_FILTER)], wl)
    except InputError:
        return None


def vega_v_magnitude(
    spectral_flux_W_nm: ArrayLike, aperture_area_m2: float, wavelength_nm: ArrayLike
) -> NDArray[np.float64] | None:
    """Vega magnitude in the Bessell V band of the irradiance at the aperture.

    .. math:: V = m_{AB}(\\mathrm{bessell\\text{-}V}) - 0.02

    (photon-weighted AB magnitude as :func:`~speclight.instrument.ab_magnitude`; the offset
    is :data:`V_AB_MINUS_VEGA`).

    Parameters
    ----------
    spectral_flux_W_nm
        (N, L) power entering the aperture [W nm-1].
    aperture_area_m2
        [m2].
    wavelength_nm
        (L,) [nm].

    Returns
    -------
    numpy.ndarray or None
        (N,) [mag], NaN where the in-band flux is <= 0; ``None`` when less than
        :data:`~speclight.instrument.bands.MIN_FRACTION_ON_GRID` of the V band is on the grid.
    """
    response = v_band_response(wavelength_nm)
    if response is None:
        return None
    mag = ab_magnitude(spectral_flux_W_nm, aperture_area_m2, wavelength_nm, response)
    return np.asarray(mag[:, 0] - V_AB_MINUS_VEGA)
