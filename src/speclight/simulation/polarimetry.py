"""Polarisation variables of the output dataset (``render.polarization``).

The render gives Stokes Q, U, V of the intensity above the atmosphere in the sky's
north-east frame (:mod:`speclight.render.polarization`). The atmosphere is taken as
unpolarising and non-depolarising: Q, U and V are attenuated by the same direct-beam
transmission as I (Rayleigh and aerosol scattering out of the beam do not change the
polarisation of the light that stays in it; the polarised sky background is not modelled).
Each band's Stokes count rates are the band integrals of Q, U, V through the same chain as
the count rate (aperture, optics, QE, band response), and ``dolp``, ``aolp`` come from them.
"""

from __future__ import annotations

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from speclight import instrument, schema
from speclight.render.polarization import dolp_aolp
from speclight.scenario import LoadedScenario
from speclight.simulation.radiometry import Radiometry

F64 = NDArray[np.float64]


def band_stokes(
    loaded: LoadedScenario,
    radiometry: Radiometry,
    wavelength_nm: F64,
    stokes_W_sr_nm: F64,
    transmission: F64,
    range_m: F64,
) -> F64:
    """Band Stokes count rates (N, B, 3) [s-1] of Q, U, V (N, L, 3), through the atmosphere."""
    sc = loaded.scenario
    area = instrument.aperture_area_m2(
        sc.telescope.aperture_diameter_m, sc.telescope.obstruction_diameter_m
    )
    ones = np.ones(wavelength_nm.size)
    kernel = radiometry.band_response * radiometry.qe
    out = []
    for c in range(3):
        flux = instrument.spectral_flux_W_nm(stokes_W_sr_nm[..., c], transmission, area, range_m)
        out.append(
            instrument.count_rate_per_s(flux, wavelength_nm, radiometry.optics, ones, kernel)
        )
    return np.stack(out, axis=-1)


def add_polarization(
    ds: xr.Dataset,
    loaded: LoadedScenario,
    wavelength_nm: F64,
    stokes_W_sr_nm: F64,
    transmission: F64,
    range_m: F64,
    radiometry: Radiometry | None,
    stokes_std_W_sr_nm: F64 | None = None,
) -> xr.Dataset:
    """Add ``intensity_q/u/v`` (and their standard errors ``intensity_q/u/v_std``: 0 when
    ``stokes_std_W_sr_nm`` is None) and, with bands, ``count_rate_q/u/v``, ``dolp``, ``aolp``."""
    std = np.zeros_like(stokes_W_sr_nm) if stokes_std_W_sr_nm is None else stokes_std_W_sr_nm
    for c, name in enumerate(("intensity_q", "intensity_u", "intensity_v")):
        ds[name] = schema.variable(name, stokes_W_sr_nm[..., c])
        ds[f"{name}_std"] = schema.variable(f"{name}_std", std[..., c])
    ds.attrs["polarization_frame"] = schema.POLARIZATION_FRAME
    if radiometry is None or not radiometry.band_names:
        return ds
    rates = band_stokes(loaded, radiometry, wavelength_nm, stokes_W_sr_nm, transmission, range_m)
    for c, name in enumerate(("count_rate_q", "count_rate_u", "count_rate_v")):
        ds[name] = schema.variable(name, rates[..., c])
    dolp, aolp = dolp_aolp(radiometry.count_rate_per_s, rates[..., 0], rates[..., 1])
    ds["dolp"] = schema.variable("dolp", dolp)
    ds["aolp"] = schema.variable("aolp", aolp)
    return ds
