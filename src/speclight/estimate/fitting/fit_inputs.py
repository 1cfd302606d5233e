"""What ``speclight fit`` takes from the scenario besides its simulation: the noise of the
measured rates and the target's own band reflectance (:mod:`.fit_run`, "Albedo")."""

from __future__ import annotations

from typing import Any

import numpy as np

from speclight.estimate.fitting.fit import F64
from speclight.estimate.fitting.noise_model import PoissonNoise
from speclight.estimate.inputs.band_albedo import band_albedo, dataset_mean_source_W_m2_nm
from speclight.estimate.inputs.measured import MeasuredLightCurve
from speclight.scenario import LoadedScenario


def noise_of(loaded: LoadedScenario, lc: MeasuredLightCurve, ds: Any) -> PoissonNoise:
    """The noise of the measured rates (:mod:`.noise_model`): the model's own shot noise
    over ``instrument.exposure_s`` times the exposures averaged, with the background (sky
    and dark current) and read noise of the scenario's ``instrument.noise`` where it has
    one, Gaussian with the data's own sigmas where they give them. ``ds`` is a simulation
    of the scenario (its band responses give the sky's rate)."""
    from speclight import instrument

    sc = loaded.scenario
    background: F64 | float = 0.0
    read_e = 0.0
    noise = sc.instrument.noise
    if noise is not None and noise.enabled:
        wl = ds["wavelength"].values.astype(float)
        area = instrument.aperture_area_m2(
            sc.telescope.aperture_diameter_m, sc.telescope.obstruction_diameter_m
        )
        kernel = (
            ds["band_response"].transpose("band", "wavelength").values
            * ds["detector_qe"].transpose("band", "wavelength").values
        )
        sky = instrument.sky_count_rate_per_s(
            noise.sky_background_mag_arcsec2, area, wl, ds["optics_transmission"].values,
            np.ones(wl.size), kernel,
            background_aperture_radius_arcsec=noise.aperture_radius_arcsec,
        )  # fmt: skip
        background = np.asarray(sky, dtype=float) + noise.dark_current_e_per_s
        read_e = float(noise.read_noise_e)
    return PoissonNoise.of(
        lc.rate_per_s.shape, sc.instrument.exposure_s, lc.n_samples, background, read_e,
        given_sigma=lc.sigma_per_s,
    )  # fmt: skip


def band_reflectance(loaded: LoadedScenario, ds: Any) -> F64:
    """The scenario's target reflectance per band (module doc: Albedo) [1] (B,)."""
    from speclight.simulation.reflection import build_target

    target = build_target(loaded)
    wl = ds["wavelength"].values.astype(float)
    spectrum, total = np.zeros(wl.size), 0.0
    for part in target.parts:
        mat = part.material
        refl = mat.diffuse_reflectance if mat.bsdf == "plastic" else mat.reflectance
        assert refl is not None
        spectrum += part.area_m2 * refl.evaluate(wl)
        total += part.area_m2
    response = (
        ds["band_response"].transpose("band", "wavelength").values
        * ds["optics_transmission"].values[None, :]
        * ds["detector_qe"].transpose("band", "wavelength").values
    )
    return band_albedo(spectrum / total, response, wl, dataset_mean_source_W_m2_nm(ds))


__all__ = ["band_reflectance", "noise_of"]
