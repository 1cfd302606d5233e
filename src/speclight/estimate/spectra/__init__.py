"""Spectra from band measurements: upsampling, unmixing, endmembers, accuracy against truth.

* :mod:`.upsample_run` (``speclight upsample``) over :mod:`.upsampling` (a spectrum from n
  band albedos: sigmoid polynomial, eq. 3-4);
* :mod:`.unmix_run` (``speclight unmix``) over :mod:`.unmixing` (x = S a: LS, NNLS,
  NNLS + normalisation, FCLS), :mod:`.unmixing_epochs` (per-epoch signatures),
  :mod:`.endmembers` (ATGP, PCA, N-FINDR) and :mod:`.endmember_spectra` (files or the
  scenario's materials, their band signatures);
* against ground truth: :mod:`.ground_truth` (signatures, true contributions),
  :mod:`.unmix_truth` (what ``unmix`` adds to ABUND.nc), :mod:`.accuracy` (confusion
  matrix, errors, spectral angle).
"""

from speclight.estimate.spectra.accuracy import (
    confusion_matrix,
    in_reference_units,
    mean_absolute_share_error,
    spectral_angle_rad,
)
from speclight.estimate.spectra.endmember_spectra import (
    endmembers_from_files,
    endmembers_from_scenario,
)
from speclight.estimate.spectra.endmembers import EndmemberResult, extract_endmembers
from speclight.estimate.spectra.ground_truth import (
    fractions,
    material_signatures,
    true_contributions,
)
from speclight.estimate.spectra.unmix_run import unmix_measured
from speclight.estimate.spectra.unmixing import UNMIX_METHODS, UnmixResult, unmix
from speclight.estimate.spectra.unmixing_epochs import unmix_per_epoch
from speclight.estimate.spectra.upsample_run import read_fit_albedos, upsample_scenario
from speclight.estimate.spectra.upsampling import UpsampledSpectrum, upsample

__all__ = [
    "UNMIX_METHODS",
    "EndmemberResult",
    "UnmixResult",
    "UpsampledSpectrum",
    "confusion_matrix",
    "endmembers_from_files",
    "endmembers_from_scenario",
    "extract_endmembers",
    "fractions",
    "in_reference_units",
    "material_signatures",
    "mean_absolute_share_error",
    "read_fit_albedos",
    "spectral_angle_rad",
    "true_contributions",
    "unmix",
    "unmix_measured",
    "unmix_per_epoch",
    "upsample",
    "upsample_scenario",
]
