"""Rotation period of a pass (``speclight period``, docs/period.md).

* :mod:`.period_run`: the command's run (:func:`estimate_period`): light curves in,
  PERIOD.json out;
* plain-array cores: :mod:`.periodogram` (multi-band multi-harmonic Lomb-Scargle),
  :mod:`.peak_refinement` (the best peak refined with the model the light curve needs, and
  its standard deviation), :mod:`.period_fap` (false-alarm probability, bootstrap),
  :mod:`.period_decision` (photometric or rotation period), :mod:`.synodic` (synodic and
  sidereal periods);
* :mod:`.period_geometry`: the phase-angle bisector and the spin axis of a scenario.
"""

from speclight.estimate.period.period_result import PeriodResult
from speclight.estimate.period.period_run import estimate_period

__all__ = ["PeriodResult", "estimate_period"]
