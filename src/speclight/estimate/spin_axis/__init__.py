"""Spin axis and rotation phase against a reflectivity map (``speclight spin-axis``,
docs/spin-axis.md).

* :mod:`.spin_axis_run`: the command's run (:func:`spin_axis_measured`): scenario, measured
  pass and map in; :mod:`.spin_axis_dataset`: AXIS.nc out;
* plain-array cores: :mod:`.spin_axis_core` (the grid search, :func:`spin_axis_search`),
  :mod:`.spin_axis_grid` (every candidate's misfit), :mod:`.spin_axis_lookup` (the map in
  the spin frame), :mod:`.spin_axis_ranging` (laser light curves and range offsets),
  :mod:`.spin_axis_misfit` (one candidate, the map's own interpolation);
* refinement: :mod:`.spin_axis_refine` (Nelder-Mead, gradient, Gauss-Newton, SLSQP) with
  :mod:`.spin_axis_gradient` (analytic derivatives) and :mod:`.spin_axis_continuation`
  (coarsened maps);
* the period: :mod:`.spin_axis_period` (a synodic period turned sidereal per axis),
  :mod:`.spin_axis_period_scan` (the grid under the period as given, or scanned when free),
  :mod:`.spin_axis_answer` (the refinement keeping axis and period consistent);
* :mod:`.spin_axis_confidence`: sigmas, the confidence region and what cannot be trusted;
* :mod:`.spin_axis_limits`: the search's memory and time, checked first.
"""

from speclight.estimate.spin_axis.spin_axis_core import SpinAxisResult, spin_axis_search
from speclight.estimate.spin_axis.spin_axis_run import spin_axis_measured

__all__ = ["SpinAxisResult", "spin_axis_measured", "spin_axis_search"]
