"""Estimation: from measured (or simulated) light curves back to the target's surface.

Plain-array cores first (numpy in, numpy out; see ``docs/design.md``); the commands of the
command line are built on them:

* :mod:`.measured`: measured light curves in (CSV, speclight NetCDF), binning;
* :mod:`.unmixing`: the linear mixing model x = S a (LS, NNLS, NNLS + normalisation, FCLS);
* :mod:`.endmembers`: endmember extraction (ATGP, PCA, N-FINDR);
* :mod:`.upsampling`: spectra from n band albedos (sigmoid polynomial, eq. 3-4);
* :mod:`.fit`, :mod:`.roughness_fit`, :mod:`.scenario_fit`: band albedos and roughness
  fitted to measured count rates (``speclight fit``).
"""

from speclight.estimate.endmembers import EndmemberResult, extract_endmembers
from speclight.estimate.fit import fit_scales, shot_noise_sigma
from speclight.estimate.measured import MeasuredLightCurve, bin_light_curve, read_measured
from speclight.estimate.roughness_fit import fit_roughness
from speclight.estimate.scenario_fit import FitResult, fit_scenario
from speclight.estimate.unmixing import UNMIX_METHODS, UnmixResult, unmix
from speclight.estimate.upsampling import UpsampledSpectrum, upsample

__all__ = [
    "UNMIX_METHODS",
    "EndmemberResult",
    "FitResult",
    "MeasuredLightCurve",
    "UnmixResult",
    "UpsampledSpectrum",
    "bin_light_curve",
    "extract_endmembers",
    "fit_roughness",
    "fit_scales",
    "fit_scenario",
    "read_measured",
    "shot_noise_sigma",
    "unmix",
    "upsample",
]
