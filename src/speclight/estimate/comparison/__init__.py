"""Simulated against observed magnitudes (``speclight compare``, docs/compare.md).

* :mod:`.compare_run`: the command's run (:func:`compare`), one simulation per site;
* :mod:`.compare_stats`: the residual statistics.

The observations are read by :mod:`speclight.estimate.inputs.observations`.
"""

from speclight.estimate.comparison.compare_run import CompareResult, compare

__all__ = ["CompareResult", "compare"]
