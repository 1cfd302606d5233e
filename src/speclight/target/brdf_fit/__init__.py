"""Analytic BRDF models fitted to measured tables (``speclight brdf-fit``).

* :mod:`.analytic_forms`: the forms (Phong, ABg, binomial, microfacet) as numpy functions of
  the shading cosines, shared by the fit, the single-mode render and path mode;
* :mod:`.form_coefficients`: their coefficients, checks and the fit's parameter vectors;
* :mod:`.directional_albedo`: the white-furnace integral that every fit is held to;
* :mod:`.log_fit`: the least-squares fit in log space and its per-incidence residuals;
* :mod:`.material_yaml`: the fitted material as a scenario's material mapping.
"""
