"""Instrument stage: telescope, optics, detector, bands; photo-electron rates and magnitudes.

Plain-array functions: :func:`aperture_area_m2`, :func:`spectral_flux_W_nm`,
:func:`spectral_curve` (optics / QE), :func:`band_response`, :func:`count_rate_per_s`,
:func:`ab_magnitude`, :func:`standard_magnitude`, :func:`vega_v_magnitude`,
:func:`sky_count_rate_per_s`, :func:`simulate_measurement`.
"""

from speclight.instrument.bands import (
    Band,
    band_response,
    filter_band,
    gaussian_band,
    parse_band,
    speclite_filter_names,
    table_band,
)
from speclight.instrument.curves import DETECTOR_PRESETS, load_preset, spectral_curve
from speclight.instrument.magnitudes import (
    STANDARD_RANGE_M,
    V_AB_MINUS_VEGA,
    standard_magnitude,
    vega_v_magnitude,
)
from speclight.instrument.noise import simulate_measurement, sky_count_rate_per_s
from speclight.instrument.photometry import (
    AB_ZERO_W_M2_HZ,
    ab_magnitude,
    ab_reference_W_m2_nm,
    count_rate_per_s,
    reflectance_factor_m2_sr,
)
from speclight.instrument.telescope import aperture_area_m2, spectral_flux_W_nm
from speclight.wavelength_grid import bin_average, bin_edges_nm, bin_widths_nm

__all__ = [
    "AB_ZERO_W_M2_HZ",
    "DETECTOR_PRESETS",
    "STANDARD_RANGE_M",
    "V_AB_MINUS_VEGA",
    "Band",
    "ab_magnitude",
    "ab_reference_W_m2_nm",
    "aperture_area_m2",
    "band_response",
    "bin_average",
    "bin_edges_nm",
    "bin_widths_nm",
    "count_rate_per_s",
    "filter_band",
    "gaussian_band",
    "load_preset",
    "parse_band",
    "reflectance_factor_m2_sr",
    "simulate_measurement",
    "sky_count_rate_per_s",
    "speclite_filter_names",
    "spectral_curve",
    "spectral_flux_W_nm",
    "standard_magnitude",
    "table_band",
    "vega_v_magnitude",
]
