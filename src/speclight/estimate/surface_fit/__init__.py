"""Analytic BRDFs of a target's surfaces fitted to observed magnitudes
(``speclight fit SCENARIO OBSERVATIONS --free brdf[,attitude]``, docs/surface-fit.md).

* :mod:`.surface_fit_run`: the command's run (:func:`fit_surfaces`);
* :mod:`.surface_records`: the fitted surfaces' lit, visible elements, rendered once;
* :mod:`.surface_model`: magnitudes from the BRDF coefficients on those elements;
* :mod:`.surface_parameters`: which coefficients of each model are fitted, and how;
* :mod:`.robust_fit`: robust least squares, Jacobian and bootstrap uncertainties, halves
  by night for the cross-validation;
* :mod:`.surface_fit_report`: SURFACES.json and the terminal's lines.
"""

from speclight.estimate.surface_fit.surface_fit_run import SurfaceFitResult, fit_surfaces

__all__ = ["SurfaceFitResult", "fit_surfaces"]
