"""Relative optical airmass and surface pressure of the observing site, through pvlib.

Both are closed-form published formulas that pvlib keeps (``pvlib.atmosphere``); this module
adds the elevation convention (apparent elevation in degrees, NaN at and below the horizon)
and the validation of the site altitude. pvlib is an engine (``speclight[atmosphere]``):
imported when a value is computed, never on import, so that a scenario loads without it
and a missing pvlib is reported by the scenario's engine check.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError


def airmass(elevation_deg: ArrayLike) -> NDArray[np.float64]:
    """Relative optical airmass of a line of sight (Kasten & Young 1989, via pvlib).

    .. math:: m = \\frac{1}{\\sin h + 0.50572\\,(h + 6.07995^\\circ)^{-1.6364}}

    with :math:`h` the apparent elevation in degrees
    (``pvlib.atmosphere.get_relative_airmass(90 - h, model="kastenyoung1989")``). The
    formula includes the curvature of the Earth and refraction of a standard atmosphere; it
    is 1 at the zenith and about 38 at the horizon.

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
    from pvlib.atmosphere import get_relative_airmass

    h = np.asarray(elevation_deg, dtype=np.float64)
    out = np.full(h.shape, np.nan)
    up = np.isfinite(h) & (h > 0.0) & (h <= 90.0)
    zenith = 90.0 - h[up]
    out[up] = np.asarray(get_relative_airmass(zenith, model="kastenyoung1989"), dtype=float)
    return out


def pressure_from_altitude(site_altitude_m: float) -> float:
    """Mean surface pressure at a site from the barometric formula (``pvlib.atmosphere.alt2pres``).

    The standard troposphere: 101325 Pa and 288.15 K at sea level, a lapse rate of
    6.5 K km-1 and dry air.

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
    from pvlib.atmosphere import alt2pres

    return float(alt2pres(h))
