"""What every estimator reads, checked once: measured light curves, observations, band
reflectance factors, band responses, source spectra, and the up-front limits.

* :mod:`.measured` (with :mod:`.measured_csv`, the CSV, and :mod:`.measured_checks`, the
  checks every input passes): measured light curves in (CSV, speclight NetCDF), binning;
* :mod:`.observations`: the OBSERVATIONS CSV of observed magnitudes (``speclight compare``);
* :mod:`.reflectance_factors`: band reflectance factors (eq. 5) of a dataset or of count
  rates with a scenario;
* :mod:`.band_responses`: band curve x optics x QE of a scenario or a dataset;
* :mod:`.source_spectrum`: the source at the aperture (Sun, coaxial lasers);
* :mod:`.geometry_match`: can a scenario be the measured target (before its geometry is used);
* :mod:`.cost_limits`: memory and time of what a user's options make large, checked first.
"""

from speclight.estimate.inputs.band_responses import BandResponses, scenario_band_responses
from speclight.estimate.inputs.measured import MeasuredLightCurve, bin_light_curve, read_measured
from speclight.estimate.inputs.observations import Observations, read_observations
from speclight.estimate.inputs.reflectance_factors import read_reflectance_factors

__all__ = [
    "BandResponses",
    "MeasuredLightCurve",
    "Observations",
    "bin_light_curve",
    "read_measured",
    "read_observations",
    "read_reflectance_factors",
    "scenario_band_responses",
]
