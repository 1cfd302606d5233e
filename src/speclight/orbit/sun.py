"""Geocentric position of the Sun from the JPL DE421 ephemeris shipped in skyfield-data.

The position is the *apparent* geocentric one (light-time, aberration and gravitational
deflection applied, GCRS axes; skyfield ``earth.at(t).observe(sun).apparent()``): it is
the direction along which sunlight arrives in the Earth-centred frame, hence the axis of
the Earth's shadow and the illumination direction at a near-Earth target (the annual
aberration, 20", is the largest of these effects). Ephemeris: Folkner et al. (2009), "The
Planetary and Lunar Ephemeris DE 421", IPN Progress Report 42-178.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from skyfield.timelib import Time

from speclight.constants import AU_M
from speclight.orbit.frames import FAST_MIN_EPOCHS, TimeLike, as_time, hourly_interpolated
from speclight.orbit.timescale import load_ephemeris


def _sun_apparent_m(t: Time) -> NDArray[np.float64]:
    eph = load_ephemeris()
    apparent = eph["earth"].at(t).observe(eph["sun"]).apparent()
    return np.asarray(apparent.position.m, dtype=np.float64).T.reshape(-1, 3)


def sun_position_gcrs_m(t: TimeLike, exact: bool | None = None) -> NDArray[np.float64]:
    """Apparent geocentric position of the Sun, GCRS axes.

    Parameters
    ----------
    t
        Epochs (N), skyfield ``Time`` or UTC ``datetime64``.
    exact
        True: skyfield at every epoch. False: skyfield on a 1 h grid and 10-point
        Lagrange interpolation (the geocentric Sun moves 0.04 deg per hour along a
        smooth curve; the interpolation error is below a millimetre). None (default):
        interpolate for N >= ``FAST_MIN_EPOCHS``.

    Returns
    -------
    ndarray
        (N, 3) position [m].
    """
    t = as_time(t)
    n = int(np.size(t.whole))
    if exact is None:
        exact = n < FAST_MIN_EPOCHS
    if exact:
        return _sun_apparent_m(t)
    return hourly_interpolated(t, _sun_apparent_m)


def sun_distance_au(t: TimeLike) -> NDArray[np.float64]:
    """Earth-Sun distance [au] (light-time corrected), shape (N,)."""
    return np.linalg.norm(sun_position_gcrs_m(t), axis=1) / AU_M
