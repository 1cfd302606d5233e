"""Band albedos and roughness fitted to measured count rates (``speclight fit``, docs/fit.md).

* :mod:`.fit_run`: the command's run (:func:`fit_scenario`): the scenario simulated at the
  measured epochs, then fitted; :mod:`.fit_run_roughness` its roughness part;
* plain-array cores: :mod:`.fit` (band scales in closed form, uncertainties),
  :mod:`.fit_bins` (``bin_s``: measurements and model averaged alike), :mod:`.roughness_fit`
  (SLSQP), :mod:`.gradient_fit` (trust region on analytic derivatives);
* :mod:`.roughness_gradient`: count rates and their roughness derivatives from one render.
"""

from speclight.estimate.fitting.fit import fit_scales, shot_noise_sigma
from speclight.estimate.fitting.fit_run import FitResult, fit_scenario
from speclight.estimate.fitting.roughness_fit import fit_roughness

__all__ = ["FitResult", "fit_roughness", "fit_scales", "fit_scenario", "shot_noise_sigma"]
