"""Radiometry stage of the pipeline: atmosphere and instrument, from the scenario."""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight import atmosphere, instrument
from speclight.atmosphere.params import AtmosphereParams
from speclight.instrument.curves import DETECTOR_PRESETS
from speclight.scenario import LoadedScenario
from speclight.scenario.sections_light import ReflectanceFile, Spectrum
from speclight.wavelength_grid import grid_from_range_nm

F64 = NDArray[np.float64]


def wavelength_grid_nm(spectrum: Spectrum) -> F64:
    """Bin centres from ``min_nm`` to ``max_nm`` (included when on the grid) [nm]."""
    return grid_from_range_nm(spectrum.min_nm, spectrum.max_nm, spectrum.step_nm)


def atmosphere_params(loaded: LoadedScenario) -> AtmosphereParams:
    """The scenario's atmosphere parameters (validated at load time), paths resolved."""
    params: AtmosphereParams = loaded.scenario.atmosphere.params
    if params.table_file is not None:
        params = replace(params, table_file=loaded.resolve(str(params.table_file)))
    return params


def atmosphere_transmission(loaded: LoadedScenario, wavelength_nm: F64, elevation_deg: F64) -> F64:
    """Direct-beam transmission (N, L) for the scenario's atmosphere model."""
    return atmosphere.transmission(
        loaded.scenario.atmosphere.model,
        wavelength_nm,
        elevation_deg,
        loaded.scenario.observer.altitude_m,
        params=atmosphere_params(loaded),
    )


def _curve_spec(loaded: LoadedScenario, spec: float | str | ReflectanceFile) -> Any:
    if isinstance(spec, ReflectanceFile):
        return loaded.resolve(spec.file)
    if isinstance(spec, str) and spec.lower() not in DETECTOR_PRESETS:
        return loaded.resolve(spec)  # a table file; spectral_curve explains a bad name
    return spec


def _bands(loaded: LoadedScenario) -> list[instrument.Band]:
    out: list[instrument.Band] = []
    for band in loaded.scenario.instrument.bands:
        if band.gaussian is not None:
            out.append(
                instrument.gaussian_band(band.gaussian.center_nm, band.gaussian.sigma_nm, band.name)
            )
        elif band.filter is not None:
            out.append(instrument.filter_band(band.filter, band.name))
        elif band.file is not None:
            out.append(instrument.table_band(loaded.resolve(band.file), band.name))
        else:
            parsed = instrument.parse_band(band.name)
            out.append(parsed)
    return out


@dataclass
class Radiometry:
    """Instrument-side results (docs/output.md) and the curves that produced them."""

    band_names: list[str]
    spectral_flux_W_nm: F64
    count_rate_per_s: F64
    ab_magnitude: F64
    count_rate_measured_per_s: F64 | None
    band_response: F64
    optics: F64
    qe: F64
    reflectance_factor_m2_sr: F64 | None = None
    #: (N, B) AB magnitude above the atmosphere, and moved to 1000 km [mag]
    ab_magnitude_exo: F64 | None = None
    ab_magnitude_standard: F64 | None = None
    #: (N,) Vega V at the aperture and its standard magnitude; None off the V band [mag]
    vega_v_magnitude: F64 | None = None
    vega_v_magnitude_standard: F64 | None = None


def instrument_response(
    loaded: LoadedScenario,
    wavelength_nm: F64,
    intensity_W_sr_nm: F64,
    transmission: F64,
    range_m: F64,
    illumination_W_m2_nm: F64 | None = None,
) -> Radiometry:
    """Spectral flux at the aperture, band count rates, AB magnitudes and noisy rates.

    ``illumination_W_m2_nm`` (N, L): the irradiance on the target (the Sun's, after the
    Earth's shadow) times the transmission to the observer; with it the band reflectance
    factors are computed too (:func:`speclight.instrument.reflectance_factor_m2_sr`).
    """
    sc = loaded.scenario
    area = instrument.aperture_area_m2(
        sc.telescope.aperture_diameter_m, sc.telescope.obstruction_diameter_m
    )
    optics = instrument.spectral_curve(
        _curve_spec(loaded, sc.instrument.optics_transmission),
        wavelength_nm,
        field="instrument.optics_transmission",
    )
    common_qe = instrument.spectral_curve(
        _curve_spec(loaded, sc.instrument.detector_qe),
        wavelength_nm,
        field="instrument.detector_qe",
    )
    qe = np.array(
        [
            common_qe
            if band.detector_qe is None
            else instrument.spectral_curve(
                _curve_spec(loaded, band.detector_qe),
                wavelength_nm,
                field=f"instrument.bands.{i}.detector_qe",
            )
            for i, band in enumerate(sc.instrument.bands)
        ]
    ).reshape(-1, wavelength_nm.size)
    bands = _bands(loaded)
    response = (
        instrument.band_response(bands, wavelength_nm)
        if bands
        else np.zeros((0, wavelength_nm.size))
    )
    flux = instrument.spectral_flux_W_nm(intensity_W_sr_nm, transmission, area, range_m)
    # Each band's own detector: fold its QE into the response (the integrand is a product).
    ones = np.ones(wavelength_nm.size)
    rate = instrument.count_rate_per_s(flux, wavelength_nm, optics, ones, response * qe)
    with np.errstate(divide="ignore", invalid="ignore"):
        mag = instrument.ab_magnitude(flux, area, wavelength_nm, response)
        magnitudes = _more_magnitudes(intensity_W_sr_nm, range_m, flux, area, wavelength_nm)
        exo = instrument.ab_magnitude(magnitudes["exo_flux"], area, wavelength_nm, response)
    measured = None
    noise = sc.instrument.noise
    if noise is not None and noise.enabled and bands:
        sky = instrument.sky_count_rate_per_s(
            noise.sky_background_mag_arcsec2,
            area,
            wavelength_nm,
            optics,
            ones,
            response * qe,
            background_aperture_radius_arcsec=noise.aperture_radius_arcsec,
        )
        finite = np.isfinite(rate)
        measured = np.full_like(rate, np.nan)
        measured[finite] = instrument.simulate_measurement(
            rate[finite],
            sc.instrument.exposure_s,
            sky_count_rate_per_s=np.broadcast_to(sky, rate.shape)[finite],
            dark_current_e_per_s=noise.dark_current_e_per_s,
            read_noise_e=noise.read_noise_e,
            seed=noise.seed,
        )
    factor = None
    if illumination_W_m2_nm is not None and bands:
        factor = instrument.reflectance_factor_m2_sr(
            rate, range_m, area, illumination_W_m2_nm, wavelength_nm, optics, ones, response * qe
        )
    return Radiometry(
        band_names=[b.name for b in bands],
        spectral_flux_W_nm=flux,
        count_rate_per_s=rate,
        ab_magnitude=mag,
        count_rate_measured_per_s=measured,
        band_response=response,
        optics=optics,
        qe=qe,
        reflectance_factor_m2_sr=factor,
        ab_magnitude_exo=exo,
        ab_magnitude_standard=instrument.standard_magnitude(exo, range_m),
        vega_v_magnitude=magnitudes["v"],
        vega_v_magnitude_standard=magnitudes["v_standard"],
    )


def _more_magnitudes(
    intensity_W_sr_nm: F64, range_m: F64, flux: F64, area_m2: float, wavelength_nm: F64
) -> dict[str, Any]:
    """The exo-atmospheric flux (N, L) and the Vega V magnitudes (N,) (None off the V band)."""
    exo_flux = instrument.spectral_flux_W_nm(
        intensity_W_sr_nm, np.ones_like(intensity_W_sr_nm), area_m2, range_m
    )
    v = instrument.vega_v_magnitude(flux, area_m2, wavelength_nm)
    v_exo = instrument.vega_v_magnitude(exo_flux, area_m2, wavelength_nm)
    v_std = None if v_exo is None else instrument.standard_magnitude(v_exo, range_m)
    return {"exo_flux": exo_flux, "v": v, "v_standard": v_std}


def band_reflectance_factor(
    loaded: LoadedScenario,
    radiometry: Radiometry,
    wavelength_nm: F64,
    intensity_W_sr_nm: F64,
    transmission: F64,
    range_m: F64,
    illumination_W_m2_nm: F64,
) -> F64:
    """Band reflectance factors (N, B) [m2 sr-1] of an intensity (N, L), e.g. one material's.

    The chain of :func:`instrument_response` with its curves (``radiometry``): spectral flux
    at the aperture, band count rates, then
    :func:`speclight.instrument.reflectance_factor_m2_sr` for the illumination
    ``illumination_W_m2_nm`` (N, L) (irradiance at the target x transmission). Linear in the
    intensity, so the factors of intensities that sum to the total sum to the total's.
    """
    sc = loaded.scenario
    area = instrument.aperture_area_m2(
        sc.telescope.aperture_diameter_m, sc.telescope.obstruction_diameter_m
    )
    ones = np.ones(wavelength_nm.size)
    kernel = radiometry.band_response * radiometry.qe
    flux = instrument.spectral_flux_W_nm(intensity_W_sr_nm, transmission, area, range_m)
    rate = instrument.count_rate_per_s(flux, wavelength_nm, radiometry.optics, ones, kernel)
    return instrument.reflectance_factor_m2_sr(
        rate, range_m, area, illumination_W_m2_nm, wavelength_nm, radiometry.optics, ones, kernel
    )


__all__ = [
    "Radiometry",
    "atmosphere_transmission",
    "band_reflectance_factor",
    "instrument_response",
    "wavelength_grid_nm",
]
