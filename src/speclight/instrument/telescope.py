"""Telescope collecting area and the spectral power entering the aperture."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError


def aperture_area_m2(aperture_diameter_m: float, obstruction_diameter_m: float = 0.0) -> float:
    """Collecting area of a circular aperture with a central obstruction.

    .. math:: A = \\frac{\\pi}{4}(D^2 - d^2)

    Parameters
    ----------
    aperture_diameter_m
        Clear aperture diameter D [m], > 0.
    obstruction_diameter_m
        Diameter d of the central obstruction (secondary mirror) [m], 0 <= d < D.

    Returns
    -------
    float
        Area [m2].
    """
    d_ap = float(aperture_diameter_m)
    d_ob = float(obstruction_diameter_m)
    if not (np.isfinite(d_ap) and d_ap > 0):
        raise InputError(
            f"aperture_diameter_m = {aperture_diameter_m!r} must be > 0 (metres)",
            field="telescope.aperture_diameter_m",
        )
    if not (np.isfinite(d_ob) and 0 <= d_ob < d_ap):
        raise InputError(
            f"obstruction_diameter_m = {obstruction_diameter_m!r} must be >= 0 and smaller "
            f"than the aperture diameter {d_ap:g} m",
            field="telescope.obstruction_diameter_m",
        )
    return 0.25 * np.pi * (d_ap**2 - d_ob**2)


def spectral_flux_W_nm(
    intensity_W_sr_nm: ArrayLike,
    transmission: ArrayLike,
    aperture_area_m2: float,
    range_m: ArrayLike,
) -> NDArray[np.float64]:
    """Spectral power entering the aperture, I T A / r^2.

    The target is a point source: its radiant intensity I toward the observer, attenuated
    by the atmosphere's direct-beam transmission T, fills the solid angle A / r^2 of the
    aperture seen from the target (r >> aperture).

    Parameters
    ----------
    intensity_W_sr_nm
        Radiant intensity above the atmosphere (N, L) [W sr-1 nm-1].
    transmission
        Atmospheric direct-beam transmission (N, L) [1].
    aperture_area_m2
        Collecting area [m2], > 0.
    range_m
        Observer-target distance (N,) [m], > 0 (NaN marks an unobservable epoch).

    Returns
    -------
    numpy.ndarray
        Spectral flux (N, L) [W nm-1]; NaN where any input is NaN.
    """
    intensity = np.asarray(intensity_W_sr_nm, dtype=np.float64)
    t = np.asarray(transmission, dtype=np.float64)
    r = np.asarray(range_m, dtype=np.float64)
    if intensity.shape != t.shape or intensity.ndim != 2 or r.shape != intensity.shape[:1]:
        raise InputError(
            f"shapes must be intensity (N, L), transmission (N, L), range (N,); got "
            f"{intensity.shape}, {t.shape}, {r.shape}",
            field="spectral_flux",
        )
    if not (np.isfinite(aperture_area_m2) and aperture_area_m2 > 0):
        raise InputError(f"aperture area {aperture_area_m2!r} m2 must be > 0", field="telescope")
    if np.any(r <= 0):
        raise InputError("range_m must be > 0 (NaN for unobservable epochs)", field="range")
    return intensity * t * (aperture_area_m2 / r**2)[:, None]
