"""The noise of band reflectance factors, from the noise of the count rates behind them.

The band reflectance factor (eq. 5 of Nussbaum et al. 2022, doi:10.3390/aerospace9040214) is
linear in the count rate, so its standard deviation is ``factor x sigma_rate / rate``. The
rates' ``sigma_rate`` is the one the data give (a CSV's sigma column, a dataset's
``count_rate_sigma``); where they give none it is the scenario's noise model, that of
:func:`speclight.instrument.simulate_measurement`: a background-subtracted rate measured in
``exposure_s`` has the variance ``((S + B + D) t + sigma_r^2) / t^2`` (signal S, sky B and
dark D rates, read noise sigma_r), divided by the number of exposures averaged into a bin.
Without a noise section in the scenario only the shot noise of the signal is left (a lower
bound of the noise).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.inputs.band_responses import BandResponses
from speclight.estimate.inputs.measured import MeasuredLightCurve

if TYPE_CHECKING:
    from speclight.scenario import LoadedScenario

F64 = NDArray[np.float64]


def model_rate_sigma_per_s(
    rate_per_s: F64,
    n_samples: NDArray[np.int64],
    loaded: LoadedScenario,
    bands: BandResponses,
) -> F64:
    """Standard deviation (N, B) [s-1] of measured rates by the scenario's noise model.

    ``rate_per_s`` (N, B) the measured rates (negative ones count as 0 electrons of signal),
    ``n_samples`` (N,) exposures averaged into each, ``bands`` the responses (band x optics x
    QE) that the sky enters through.
    """
    from speclight import instrument

    sc = loaded.scenario
    t = float(sc.instrument.exposure_s)
    noise = sc.instrument.noise
    dark = read = 0.0
    background: F64 | float = 0.0
    if noise is not None and noise.enabled:
        tel = sc.telescope
        area = instrument.aperture_area_m2(tel.aperture_diameter_m, tel.obstruction_diameter_m)
        ones = np.ones(bands.wavelength_nm.size)
        background = instrument.sky_count_rate_per_s(
            noise.sky_background_mag_arcsec2,
            area,
            bands.wavelength_nm,
            ones,
            ones,
            bands.response,
            background_aperture_radius_arcsec=noise.aperture_radius_arcsec,
        )
        dark, read = noise.dark_current_e_per_s, noise.read_noise_e
    sky = np.asarray(background, dtype=np.float64)
    signal = np.maximum(np.asarray(rate_per_s, dtype=np.float64), 0.0)
    variance = ((signal + sky + dark) * t + read**2) / t**2
    n = np.maximum(np.asarray(n_samples, dtype=np.float64), 1.0)[:, None]
    return np.asarray(np.sqrt(variance / n), dtype=np.float64)


def factor_sigma(
    factor: F64,
    rates: MeasuredLightCurve | None,
    loaded: LoadedScenario | None,
    bands: BandResponses,
) -> F64 | None:
    """Standard deviation (N, B) [m2 sr-1] of the band reflectance factors (module doc).

    ``rates`` are the measured rates behind ``factor`` (same epochs and bands). None where
    neither the data nor a scenario say what the noise is (``rates`` missing, or without
    sigma and ``loaded`` None).
    """
    if rates is None or rates.rate_per_s.shape != factor.shape:
        return None
    rate = rates.rate_per_s
    sigma = rates.sigma_per_s
    if sigma is None:
        if loaded is None:
            return None
        sigma = model_rate_sigma_per_s(rate, rates.n_samples, loaded, bands)
    with np.errstate(invalid="ignore", divide="ignore"):
        out = np.abs(factor) * sigma / np.abs(rate)
    return np.asarray(np.where(np.abs(rate) > 0, out, np.nan), dtype=np.float64)
