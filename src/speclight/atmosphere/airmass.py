"""Relative optical airmass and surface pressure of the observing site.

Both are closed-form published formulas; they feed every atmosphere model.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError

#: Standard sea-level pressure [Pa] (ICAO Standard Atmosphere, Doc 7488).
P0_PA = 101325.0
#: Standard sea-level temperature [K].
T0_K = 288.15
#: Tropospheric temperature lapse rate [K m-1].
LAPSE_K_PER_M = 0.0065
#: Standard gravity [m s-2].
G0_M_S2 = 9.80665
#: Molar mass of dry air [kg mol-1].
M_AIR_KG_MOL = 0.0289644
#: Universal gas constant [J mol-1 K-1] (value used by the U.S. Standard Atmosphere 1976).
R_J_MOL_K = 8.31432


def airmass(elevation_deg: ArrayLike) -> NDArray[np.float64]:
    """Relative optical airmass of a line of sight (Kasten & Young 1989).

    .. math:: m = \\frac{1}{\\sin h + 0.50572\\,(h + 6.07995^\\circ)^{-1.6364}}

    with :math:`h` the apparent elevation in degrees. The formula includes the curvature
    of the Earth and refraction of a standard atmosphere; it is 1 at the zenith and about
    38 at the horizon.

    Parameters
    ----------
    elevation_deg
        Elevation of the line of sight above the horizon [deg], any shape.

    Returns
    -------
    numpy.ndarray
        Relative airmass [1], same shape; NaN where the elevation is <= 0 or NaN.

    References
    ----------
    F. Kasten and A. T. Young, "Revised optical air mass tables and approximation
    formula", Applied Optics 28(22), 4735-4738 (1989), doi:10.1364/AO.28.004735.
    """
    h = np.asarray(elevation_deg, dtype=np.float64)
    out = np.full(h.shape, np.nan)
    up = np.isfinite(h) & (h > 0.0) & (h <= 90.0)
    hu = h[up]
    out[up] = 1.0 / (np.sin(np.radians(hu)) + 0.50572 * (hu + 6.07995) ** -1.6364)
    return out


def pressure_from_altitude(site_altitude_m: float) -> float:
    """Mean surface pressure at a site from the barometric formula of the troposphere.

    .. math:: p = p_0\\,(1 - L h / T_0)^{g_0 M / (R L)}

    Parameters
    ----------
    site_altitude_m
        Site altitude above mean sea level [m], -500 to 11000 (troposphere).

    Returns
    -------
    float
        Pressure [Pa].

    References
    ----------
    U.S. Standard Atmosphere, 1976 (NOAA-S/T 76-1562), eq. 33a; identical to the ICAO
    Standard Atmosphere (ICAO Doc 7488/3, 1993) below 11 km.
    """
    h = float(site_altitude_m)
    if not np.isfinite(h) or h < -500.0 or h > 11000.0:
        raise InputError(
            f"site altitude {site_altitude_m!r} m is outside -500..11000 m "
            "(the troposphere, where the barometric formula holds); give the observer's "
            "altitude above mean sea level in metres",
            field="observer.altitude_m",
        )
    exponent = G0_M_S2 * M_AIR_KG_MOL / (R_J_MOL_K * LAPSE_K_PER_M)
    return P0_PA * (1.0 - LAPSE_K_PER_M * h / T0_K) ** exponent
