"""What ``speclight period`` found, and PERIOD.json (:meth:`PeriodResult.to_json`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from speclight.estimate.period.analytic_fap import AnalyticFap
from speclight.estimate.period.outliers import Outliers
from speclight.estimate.period.peak_refinement import Peak
from speclight.estimate.period.period_decision import MIN_CYCLES, RotationDecision
from speclight.estimate.period.period_fap import BootstrapMaxima
from speclight.estimate.period.periodogram import F64, BandSeries
from speclight.estimate.period.search_edge import SearchEdge
from speclight.estimate.period.synodic import SynodicCorrection
from speclight.estimate.period.two_frequencies import TumblingTest

#: False-alarm probability below which a period is detected.
DETECTION_FAP = 0.01
#: Noise level beside the peak (:mod:`.analytic_fap`) above which the detrended light curve
#: is said to vary slowly (red residuals), for the lower bound of the period.
SLOW_NOISE_LEVEL = 2.0


@dataclass
class PeriodResult:
    """Everything ``speclight period`` found (``to_json`` gives PERIOD.json)."""

    series: BandSeries
    band_names: list[str]
    frequency_hz: F64
    power: F64
    candidates: list[tuple[float, float]]
    peak: Peak
    harmonics: int
    analytic: AnalyticFap
    bootstrap: BootstrapMaxima | None
    decision: RotationDecision
    synodic: SynodicCorrection | None
    n_epochs: int
    source: str
    outliers: Outliers | None = None
    tumbling: TumblingTest | None = None
    rising: bool = False
    notices: list[str] = field(default_factory=list)
    edge: SearchEdge | None = None

    @property
    def best_power(self) -> float:
        """The periodogram's highest power."""
        return float(np.nanmax(self.power))

    @property
    def false_alarm_probability(self) -> float:
        """Of the best peak: the bootstrap's Gumbel fit where it ran, else analytic; both
        on the power divided by the noise level beside the peak (:mod:`.analytic_fap`)."""
        if self.bootstrap is not None:
            return self.bootstrap.false_alarm_probability(
                self.best_power / self.analytic.noise_level
            )
        return self.analytic.fap(self.best_power)

    def power_at(self, fap: float) -> float:
        """The power of false-alarm probability ``fap`` at the best peak's noise level."""
        if self.bootstrap is not None:
            return self.bootstrap.power_at(fap) * self.analytic.noise_level
        return self.analytic.power_at(fap)

    @property
    def detected(self) -> bool:
        """A period in the searched range: false-alarm probability below
        :data:`DETECTION_FAP`, and the best peak not at the longest period searched with the
        power rising beyond it."""
        return bool(self.false_alarm_probability < DETECTION_FAP and not self.rising)

    @property
    def period_lower_bound_s(self) -> float | None:
        """Without a detection, where the light curve varies slowly (power rising to the
        longest period searched, or red residuals): the longest period searched [s]."""
        slow = self.rising or self.analytic.noise_level > SLOW_NOISE_LEVEL
        if self.detected or not slow:
            return None
        return float(1.0 / self.frequency_hz[0])

    @property
    def period_s(self) -> float:
        """The rotation period: sidereal where corrected, else synodic; NaN when none is
        detected."""
        if not self.detected:
            return float("nan")
        if self.synodic is not None and self.synodic.sidereal_period_s is not None:
            return self.synodic.sidereal_period_s
        return self.decision.rotation_period_s

    @property
    def statistical_std_s(self) -> float:
        """Standard deviation of the rotation period from the fit alone [s]:
        ``factor P^2 sigma_f`` (the sidereal fit's where applied); NaN at an edge of the
        searched range (:mod:`.search_edge`)."""
        if self.edge is not None:
            return float("nan")
        if self.synodic is not None and self.synodic.sidereal_std_s is not None:
            return self.synodic.sidereal_std_s
        f = self.peak.frequency_hz
        return float(self.decision.factor * self.peak.frequency_std_hz / f**2)

    @property
    def synodic_std_s(self) -> float | None:
        """The synodic term [s] where the correction is not applied and the geometry is known:
        ``bound / sqrt(3)``, the standard deviation of ``P_sid - P_syn`` over spin axes
        drawn isotropically (the axis's cosine to the bisector's turning axis is uniform on
        [-1, 1], Archimedes' hat-box theorem, so the shift is uniform on +-bound)."""
        syn = self.synodic
        if syn is None or syn.applied:
            return None
        return float(syn.bound_s / np.sqrt(3.0))

    @property
    def period_std_s(self) -> float:
        """Standard deviation of the rotation period [s]: the statistical one and the
        synodic term in quadrature; NaN when no period is detected."""
        if not self.detected:
            return float("nan")
        return float(np.hypot(self.statistical_std_s, self.synodic_std_s or 0.0))

    def verdict(self) -> str:
        """One sentence: detected, tumbling, or what can be said without a period."""
        fap = self.false_alarm_probability
        lo, hi = 1.0 / self.frequency_hz[-1], 1.0 / self.frequency_hz[0]
        if self.detected:
            edge = (
                ""
                if self.edge is None
                else f", at the edge of the searched range: {self.edge.text}"
            )
            if self.tumbling is not None and self.tumbling.detected:
                return f"tumbling: {self.tumbling.text}{edge}"
            return f"period detected (false-alarm probability {fap:.2g} < {DETECTION_FAP:g}){edge}"
        why = (
            "the power rises to the longest period searched"
            if self.rising
            else f"false-alarm probability {fap:.2g} >= {DETECTION_FAP:g}"
        )
        head = f"no period detected between {lo:.4g} and {hi:.4g} s ({why})"
        default_max = abs(hi * MIN_CYCLES / self.series.span_s - 1) < 0.01
        beyond = (
            "a third of the span; one pass cannot measure it"
            if default_max
            else "the longest period searched; a larger max_period_s, up to the span, "
            "searches further"
        )
        if self.period_lower_bound_s is not None:
            return (
                f"{head}; the light curve varies more slowly (noise level beside the best "
                f"peak {self.analytic.noise_level:.3g} times the white level): if the body "
                f"rotates, its period is longer than {hi:.4g} s ({beyond}), or its light "
                "curve does not change with the rotation"
            )
        return f"{head}; the light curve shows no variation beyond its noise in that range"

    def to_json(self) -> dict[str, Any]:
        """PERIOD.json (keys documented in docs/period.md); a number that could not be
        determined (NaN) is written ``null`` and its key listed in ``undetermined``."""
        from speclight.estimate.period.period_summary import summary

        missing: list[str] = []
        out = _nulls_for_nan(summary(self), "", missing)
        if missing:
            out["undetermined"] = missing
        return dict(out)


def _nulls_for_nan(value: Any, key: str, missing: list[str]) -> Any:
    """``value`` with every non-finite float replaced by None (its key path added to
    ``missing``): JSON has no NaN."""
    if isinstance(value, dict):
        return {k: _nulls_for_nan(v, f"{key}.{k}" if key else k, missing) for k, v in value.items()}
    if isinstance(value, list):
        return [_nulls_for_nan(v, f"{key}[{i}]", missing) for i, v in enumerate(value)]
    if isinstance(value, float | np.floating) and not np.isfinite(value):
        missing.append(key)
        return None
    return value
