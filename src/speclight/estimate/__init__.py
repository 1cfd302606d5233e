"""Estimation: from measured (or simulated) light curves back to the target's surface.

Plain-array cores first (numpy in, numpy out; see ``docs/design.md``); the commands of the
command line are built on them:

* :mod:`.measured`: measured light curves in (CSV, speclight NetCDF), binning;
* :mod:`.unmixing`: the linear mixing model x = S a (LS, NNLS, NNLS + normalisation, FCLS);
* :mod:`.endmembers`: endmember extraction (ATGP, PCA, N-FINDR);
* :mod:`.upsampling`: spectra from n band albedos (sigmoid polynomial, eq. 3-4);
* :mod:`.accuracy`: confusion matrix, errors, spectral angle (unmixing against truth);
* :mod:`.ground_truth`: source-weighted material signatures, true contributions and
  fractions from per-material ground truth; :mod:`.source_spectrum`: the source at the
  aperture (Sun, coaxial lasers);
* :mod:`.upsample_io`, :mod:`.unmix_io` (with :mod:`.unmix_inputs`,
  :mod:`.endmember_spectra`, :mod:`.unmix_truth`, :mod:`.scenario_bands`): the
  ``speclight upsample`` and ``speclight unmix`` commands;
* :mod:`.fit`, :mod:`.roughness_fit`, :mod:`.scenario_fit`: band albedos and roughness
  fitted to measured count rates (``speclight fit``); with ``--method gradient``,
  :mod:`.gradient_fit` on the analytic derivatives of :mod:`.roughness_gradient`
  (:mod:`.scenario_roughness` joins them to the scenario);
* :mod:`.reflection_map` (HEALPix maps in the body frame) and :mod:`.reflection_map_io`
  (``speclight reflection-map``);
* :mod:`.reflectivity_map` (with :mod:`.reflectivity_map_store`,
  :mod:`.reflectivity_map_render`, :mod:`.reflectivity_map_task`): ``speclight
  reflectivity-map``, the target rendered over body-frame geometries into a Zarr store
  (read back by :mod:`speclight.render.map_lookup`), chunks in process or on Dask;
* :mod:`.period_io` (with :mod:`.periodogram`, :mod:`.period_fap`, :mod:`.period_decision`,
  :mod:`.synodic`, :mod:`.period_geometry`): the ``speclight period`` command;
* :mod:`.spin_axis` (with :mod:`.spin_axis_lookup`, :mod:`.spin_axis_io`): ``speclight
  spin-axis``, the grid search of the spin axis and phase against a reflectivity map;
* :mod:`.observations` (the OBSERVATIONS CSV) and :mod:`.compare` (with
  :mod:`.compare_stats`): ``speclight compare``, simulated against observed magnitudes.
"""

from speclight.estimate.accuracy import (
    confusion_matrix,
    in_reference_units,
    mean_absolute_share_error,
    spectral_angle_rad,
)
from speclight.estimate.compare import CompareResult, compare
from speclight.estimate.endmember_spectra import endmembers_from_files, endmembers_from_scenario
from speclight.estimate.endmembers import EndmemberResult, extract_endmembers
from speclight.estimate.fit import fit_scales, shot_noise_sigma
from speclight.estimate.ground_truth import fractions, material_signatures, true_contributions
from speclight.estimate.measured import MeasuredLightCurve, bin_light_curve, read_measured
from speclight.estimate.observations import Observations, read_observations
from speclight.estimate.period_io import PeriodResult, estimate_period
from speclight.estimate.reflection_map import ReflectionMap, reflection_map
from speclight.estimate.reflection_map_io import reflection_map_measured
from speclight.estimate.reflectivity_map import MapRun, reflectivity_map
from speclight.estimate.roughness_fit import fit_roughness
from speclight.estimate.scenario_bands import BandResponses, scenario_band_responses
from speclight.estimate.scenario_fit import FitResult, fit_scenario
from speclight.estimate.spin_axis import SpinAxisResult, spin_axis_search
from speclight.estimate.spin_axis_io import spin_axis_measured
from speclight.estimate.unmix_inputs import read_reflectance_factors
from speclight.estimate.unmix_io import unmix_measured
from speclight.estimate.unmixing import UNMIX_METHODS, UnmixResult, unmix
from speclight.estimate.unmixing_epochs import unmix_per_epoch
from speclight.estimate.upsample_io import read_fit_albedos, upsample_scenario
from speclight.estimate.upsampling import UpsampledSpectrum, upsample

__all__ = [
    "UNMIX_METHODS",
    "BandResponses",
    "CompareResult",
    "EndmemberResult",
    "FitResult",
    "MapRun",
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
    "reflectivity_map",
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
