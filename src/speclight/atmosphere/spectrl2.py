"""SPECTRL2 direct-beam transmission through pvlib (vectorised over epochs)."""

from __future__ import annotations

import warnings

import numpy as np
from numpy.typing import NDArray

from speclight.atmosphere.airmass_pressure import airmass, pressure_from_altitude
from speclight.atmosphere.params import AtmosphereParams
from speclight.errors import InputError
from speclight.wavelength_grid import bin_average

#: Wavelength range of SPECTRL2 [nm].
SPECTRL2_RANGE_NM = (300.0, 4000.0)


def spectrl2_transmission(
    wavelength_nm: NDArray[np.float64],
    elevation_deg: NDArray[np.float64],
    site_altitude_m: float,
    params: AtmosphereParams,
) -> NDArray[np.float64]:
    """Direct-beam transmission from the SPECTRL2 clear-sky model.

    Transmission is the direct normal irradiance over the extraterrestrial irradiance,
    both from :func:`pvlib.spectrum.spectrl2`, on pvlib's 122-wavelength grid, then
    averaged over each bin of ``wavelength_nm`` (piecewise-linear in between). The
    relative airmass is Kasten & Young's (:func:`~speclight.atmosphere.airmass`); SPECTRL2
    scales the Rayleigh and uniformly-mixed-gas paths by the surface pressure from
    :func:`~speclight.atmosphere.pressure_from_altitude`.

    Parameters
    ----------
    wavelength_nm
        Grid (L,) [nm], within 300..4000 nm.
    elevation_deg
        Elevation of each line of sight (N,) [deg].
    site_altitude_m
        Observer altitude [m].
    params
        Validated parameters (water vapour, ozone, aerosol AOD at 500 nm, Angstrom exponent).

    Returns
    -------
    numpy.ndarray
        Transmission (N, L) [1]; NaN rows where the elevation is <= 0 or NaN.

    References
    ----------
    R. E. Bird and C. Riordan, "Simple solar spectral model for direct and diffuse
    irradiance on horizontal and tilted planes at the Earth's surface for cloudless
    atmospheres", J. Climate Appl. Meteor. 25, 87-97 (1986),
    doi:10.1175/1520-0450(1986)025<0087:SSSMFD>2.0.CO;2.
    """
    import pvlib.spectrum

    lo, hi = SPECTRL2_RANGE_NM
    if wavelength_nm[0] < lo or wavelength_nm[-1] > hi:
        raise InputError(
            f"the wavelength grid {wavelength_nm[0]:g}..{wavelength_nm[-1]:g} nm leaves "
            f"SPECTRL2's range {lo:g}..{hi:g} nm; set spectrum.min_nm >= {lo:g} and "
            f"max_nm <= {hi:g}, or use atmosphere model '6s' (250..4000 nm)",
            field="atmosphere.model",
        )
    n = elevation_deg.size
    out = np.full((n, wavelength_nm.size), np.nan)
    m = airmass(elevation_deg)
    up = np.isfinite(m)
    if not np.any(up):
        return out
    zenith = 90.0 - elevation_deg[up]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        res = pvlib.spectrum.spectrl2(
            apparent_zenith=zenith,
            aoi=zenith,
            surface_tilt=0.0,
            ground_albedo=0.0,
            surface_pressure=pressure_from_altitude(site_altitude_m),
            relative_airmass=m[up],
            precipitable_water=params.water_vapour_cm,
            ozone=params.ozone_atm_cm,
            aerosol_turbidity_500nm=params.aod_500nm,
            dayofyear=np.ones(zenith.size),
            alpha=params.angstrom_exponent,
        )
    wl_src = np.asarray(res["wavelength"], dtype=np.float64)
    t_src = np.asarray(res["dni"]) / np.asarray(res["dni_extra"])  # (122, n_up)
    t_src = np.clip(np.nan_to_num(t_src, nan=0.0), 0.0, 1.0)
    out[up] = bin_average(wl_src, t_src.T, wavelength_nm, outside="edge")
    return out
