"""Estimation: from measured (or simulated) light curves back to the target's surface.

One subpackage per product, each with a ``*_run`` module that goes from files to a dataset
(the command of the same name is a thin layer over it) and its plain-array cores beside it
(numpy in, numpy out; see ``docs/design.md``):

* :mod:`.inputs`: what every estimator reads (measured light curves, observations, band
  reflectance factors, band responses, source spectra) and the up-front limits;
* :mod:`.fitting`: band albedos and roughness fitted to count rates (``speclight fit``);
* :mod:`.spectra`: spectra from bands: upsampling, unmixing, endmembers, accuracy against
  ground truth (``speclight upsample``, ``speclight unmix``);
* :mod:`.period`: the rotation period (``speclight period``);
* :mod:`.spin_axis`: the spin axis against a reflectivity map (``speclight spin-axis``);
* :mod:`.reflection_maps`: reflectance factors on a sphere in the body frame
  (``speclight reflection-map``);
* :mod:`.comparison`: simulated against observed magnitudes (``speclight compare``).

A new estimator is a copy of a sibling folder (``period/`` is the smallest). The reflectivity
map (the target rendered over body-frame geometries) is forward modelling:
:mod:`speclight.maps`.
"""

from speclight.estimate.comparison import CompareResult, compare
from speclight.estimate.fitting import (
    FitResult,
    fit_roughness,
    fit_scales,
    fit_scenario,
    shot_noise_sigma,
)
from speclight.estimate.inputs import (
    BandResponses,
    MeasuredLightCurve,
    Observations,
    bin_light_curve,
    read_measured,
    read_observations,
    read_reflectance_factors,
    scenario_band_responses,
)
from speclight.estimate.period import PeriodResult, estimate_period
from speclight.estimate.reflection_maps import (
    ReflectionMap,
    reflection_map,
    reflection_map_measured,
)
from speclight.estimate.spectra import (
    UNMIX_METHODS,
    EndmemberResult,
    UnmixResult,
    UpsampledSpectrum,
    confusion_matrix,
    endmembers_from_files,
    endmembers_from_scenario,
    extract_endmembers,
    fractions,
    in_reference_units,
    material_signatures,
    mean_absolute_share_error,
    read_fit_albedos,
    spectral_angle_rad,
    true_contributions,
    unmix,
    unmix_measured,
    unmix_per_epoch,
    upsample,
    upsample_scenario,
)
from speclight.estimate.spin_axis import SpinAxisResult, spin_axis_measured, spin_axis_search

__all__ = [
    "UNMIX_METHODS",
    "BandResponses",
    "CompareResult",
    "EndmemberResult",
    "FitResult",
    "MeasuredLightCurve",
    "Observations",
    "PeriodResult",
    "ReflectionMap",
    "SpinAxisResult",
    "UnmixResult",
    "UpsampledSpectrum",
    "bin_light_curve",
    "compare",
    "confusion_matrix",
    "endmembers_from_files",
    "endmembers_from_scenario",
    "estimate_period",
    "extract_endmembers",
    "fit_roughness",
    "fit_scales",
    "fit_scenario",
    "fractions",
    "in_reference_units",
    "material_signatures",
    "mean_absolute_share_error",
    "read_fit_albedos",
    "read_measured",
    "read_observations",
    "read_reflectance_factors",
    "reflection_map",
    "reflection_map_measured",
    "scenario_band_responses",
    "shot_noise_sigma",
    "spectral_angle_rad",
    "spin_axis_measured",
    "spin_axis_search",
    "true_contributions",
    "unmix",
    "unmix_measured",
    "unmix_per_epoch",
    "upsample",
    "upsample_scenario",
]
