"""A period at the edge of the searched range: said, and given no standard deviation.

The refinement (:mod:`.peak_refinement`) stays within the searched range, so a light curve
whose period lies beyond it gets a period pinned at the range's bound, and the curvature at
a minimum the bound cuts gives a standard deviation that means nothing (a truth at
``2 K dt`` gave an error of 5.4 of them in the calibration bench). Two cases are found:

* **at a bound**: the refined photometric frequency lies at the bound of the searched range,
  or within :data:`EDGE_STDS` of its standard deviations of it: the chi-square may fall
  further beyond the bound, so the period may lie beyond it;
* **below the shortest period**: the halves of the light curve folded at the period found,
  ``P``, agree (:func:`.period_decision.halves_test`) while ``P/2`` is shorter than the
  shortest period searched, so :func:`.period_decision.rotation_period` did not halve it:
  ``P`` may be a multiple of a period outside the range (on blind draws also a
  misidentified peak, 2/3 of the truth, whose misfit makes the halves agree). (A period beyond the
  longest one searched shows as power rising to the range's edge: no period is detected,
  :attr:`.period_result.PeriodResult.rising`.)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from speclight.estimate.period.peak_refinement import Peak
from speclight.estimate.period.period_decision import ALPHA, RotationDecision, halves_test
from speclight.estimate.period.periodogram import F64, BandSeries

#: A refined frequency within this many of its standard deviations of a bound of the searched
#: range is at that bound (the range cuts the chi-square's minimum; speclight's choice).
EDGE_STDS = 2.0
#: ... or within this fraction of a peak width ``1/span`` of it (where the standard deviation
#: is undetermined; the bounded search stops within 1e-7 peak widths of a bound).
EDGE_PEAK_WIDTHS = 1e-3


@dataclass
class SearchEdge:
    """Where the period found meets the searched range.

    Attributes
    ----------
    side
        ``"shortest"`` or ``"longest"``: the bound of the range met.
    bound_s
        That bound [s].
    text
        What it means, in words (for the verdict).
    """

    side: Literal["shortest", "longest"]
    bound_s: float
    text: str


def search_edge(
    series: BandSeries, peak: Peak, frequency_hz: F64, harmonics: int, decision: RotationDecision
) -> SearchEdge | None:
    """The edge the period found meets (module docstring), or None.

    Parameters
    ----------
    series
        The light curves.
    peak
        The refined best peak.
    frequency_hz
        The searched frequency grid [Hz] (increasing).
    harmonics
        ``K``, the periodogram's harmonics.
    decision
        The photometric and rotation periods decided from the peak.
    """
    shortest, longest = 1.0 / float(frequency_hz[-1]), 1.0 / float(frequency_hz[0])
    p_found = 1.0 / peak.frequency_hz
    dt = float(np.median(np.diff(np.unique(series.t_s))))
    shorter = (
        f"search shorter periods with a smaller min_period_s (--min-period-s; the K-th "
        f"harmonic stays below the Nyquist frequency down to 2 K dt, dt = {dt:.4g} s, so "
        "with fewer harmonics too)"
    )
    not_given = "its standard deviation is not given"
    if abs(decision.photometric_period_s / p_found - 1.0) < 1e-9:
        std = peak.frequency_std_hz
        reach = EDGE_PEAK_WIDTHS / series.span_s
        reach = max(reach, EDGE_STDS * std) if np.isfinite(std) else reach
        if frequency_hz[-1] - peak.frequency_hz <= reach:
            return SearchEdge(
                "shortest", shortest,
                f"the period found, {p_found:.6g} s, is at the shortest period searched "
                f"({shortest:.6g} s; within {EDGE_STDS:g} standard deviations): the "
                f"light curve may repeat faster; {not_given}; {shorter}",
            )  # fmt: skip
        if peak.frequency_hz - frequency_hz[0] <= reach:
            return SearchEdge(
                "longest", longest,
                f"the period found, {p_found:.6g} s, is at the longest period searched "
                f"({longest:.6g} s; within {EDGE_STDS:g} standard deviations): the "
                f"period may be longer; {not_given}; search longer periods with a larger "
                "max_period_s (--max-period-s, at most the span)",
            )  # fmt: skip
    p_ph = decision.photometric_period_s
    if p_ph / 2 >= shortest:
        return None
    test = halves_test(series, p_ph, harmonics)
    if test.differ:
        return None
    return SearchEdge(
        "shortest", shortest,
        f"the halves of the light curve folded at P = {p_ph:.6g} s agree (F = "
        f"{test.f_statistic:.3g}, p = {test.p_value:.2g} >= {ALPHA:g}): P may be a multiple "
        f"of a period below the shortest one searched ({shortest:.6g} s), such as P/2 = "
        f"{p_ph / 2:.6g} s; {not_given}; {shorter}",
    )  # fmt: skip
