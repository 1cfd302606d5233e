"""Estimation: from measured (or simulated) light curves back to the target's surface.

Plain-array cores first (numpy in, numpy out; see ``docs/design.md``); the commands of the
command line are built on them:

* :mod:`.measured`: measured light curves in (CSV, speclight NetCDF), binning;
* :mod:`.unmixing`: the linear mixing model x = S a (LS, NNLS, NNLS + normalisation, FCLS);
* :mod:`.endmembers`: endmember extraction (ATGP, PCA, N-FINDR);
* :mod:`.upsampling`: spectra from n band albedos (sigmoid polynomial, eq. 3-4);
* :mod:`.accuracy`: signal shares, confusion matrix, spectral angle (unmixing against truth);
* :mod:`.upsample_io`, :mod:`.unmix_io` (with :mod:`.unmix_inputs`, :mod:`.unmix_truth`,
  :mod:`.scenario_bands`): the ``speclight upsample`` and ``speclight unmix`` commands.
"""

from speclight.estimate.accuracy import (
    confusion_matrix,
    material_shares,
    mean_absolute_share_error,
    signal_shares,
    spectral_angle_rad,
)
from speclight.estimate.endmembers import EndmemberResult, extract_endmembers
from speclight.estimate.measured import MeasuredLightCurve, bin_light_curve, read_measured
from speclight.estimate.scenario_bands import BandResponses, scenario_band_responses
from speclight.estimate.unmix_inputs import (
    endmembers_from_files,
    endmembers_from_scenario,
    read_reflectance_factors,
)
from speclight.estimate.unmix_io import unmix_measured
from speclight.estimate.unmixing import UNMIX_METHODS, UnmixResult, unmix
from speclight.estimate.upsample_io import read_fit_albedos, upsample_scenario
from speclight.estimate.upsampling import UpsampledSpectrum, upsample

__all__ = [
    "UNMIX_METHODS",
    "BandResponses",
    "EndmemberResult",
    "MeasuredLightCurve",
    "UnmixResult",
    "UpsampledSpectrum",
    "bin_light_curve",
    "confusion_matrix",
    "endmembers_from_files",
    "endmembers_from_scenario",
    "extract_endmembers",
    "material_shares",
    "mean_absolute_share_error",
    "read_fit_albedos",
    "read_measured",
    "read_reflectance_factors",
    "scenario_band_responses",
    "signal_shares",
    "spectral_angle_rad",
    "unmix",
    "unmix_measured",
    "upsample",
    "upsample_scenario",
]
