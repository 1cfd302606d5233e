"""Sidereal period scan: chi-square of the best convex fit at each trial period.

The step. Two periods ``P`` and ``P + dP`` drift apart in rotation phase by
``T (1/P - 1/(P + dP)) ~ T dP / P^2`` turns over the data's time baseline ``T``. A fit that
starts at a trial period converges to the true one only when that drift is well below a
turn (Kaasalainen, Torppa & Muinonen 2001, Icarus 153, 37, sec. 2.3; convexinv's
``period_scan`` uses ``dP = 0.5 c P^2 / T`` with ``c = 0.8``). Here

``dP = f P^2 / T``,  ``f =`` :data:`PHASE_DRIFT` ``= 0.4`` turn between neighbouring trial
periods, so the true period is at most ``0.2`` turn (72 deg of rotation phase over the
whole baseline) from the nearest trial; every trial fit has the period free and is kept
only if it stays inside its step. The number of trials is ``T (1/P_lo - 1/P_hi) / f``:
``dP`` grows as ``P^2``, so the scan costs the same per unit of frequency.

At each trial period, fits start from :data:`N_START_POLES` poles spread over the sphere
(convexinv starts from a few poles too) and the lowest chi-square is kept.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.estimate.shape.convex_fit import ConvexSolution, fibonacci_poles, fit_convex
from speclight.estimate.shape.convex_model import HOURS_PER_DAY, ConvexModel
from speclight.progress import stage

F64 = NDArray[np.float64]
PHASE_DRIFT = 0.4
N_START_POLES = 8
SCAN_ITERATIONS = 30
MAX_TRIALS = 200_000


def period_step_h(period_h: F64 | float, baseline_d: float, drift: float = PHASE_DRIFT) -> F64:
    """Trial-period step [h] at ``period_h`` for a baseline ``baseline_d`` [d] (module doc)."""
    return np.asarray(drift * np.asarray(period_h) ** 2 / (baseline_d * HOURS_PER_DAY))


def period_grid_h(
    min_period_h: float, max_period_h: float, baseline_d: float, drift: float = PHASE_DRIFT
) -> F64:
    """Trial periods [h] from ``min_period_h`` to ``max_period_h`` (both in), spaced by
    :func:`period_step_h` (equal steps in frequency).

    Raises
    ------
    InputError
        For a range that is not ``0 < min < max``, or more than :data:`MAX_TRIALS` trials.
    """
    if not (0 < min_period_h < max_period_h < np.inf):
        raise InputError(
            f"period range [{min_period_h}, {max_period_h}] h must satisfy 0 < min < max",
            field="period_range_h",
        )
    if not baseline_d > 0:
        return np.array([min_period_h, max_period_h])
    t_h = baseline_d * HOURS_PER_DAY
    f_lo, f_hi = 1.0 / max_period_h, 1.0 / min_period_h
    n = int(np.ceil((f_hi - f_lo) * t_h / drift)) + 1
    if n > MAX_TRIALS:
        raise InputError(
            f"period range [{min_period_h}, {max_period_h}] h with a {baseline_d:.4g} d "
            f"baseline needs {n} trial periods (more than {MAX_TRIALS}); narrow the range",
            field="period_range_h",
        )
    return np.asarray(1.0 / np.linspace(f_hi, f_lo, max(n, 2)))


@dataclass(frozen=True)
class PeriodScan:
    """Result of :func:`scan_periods`.

    Attributes
    ----------
    trial_period_h
        (M,) trial periods [h].
    chi2
        (M,) lowest chi-square at each trial (inf where no fit stayed in its step).
    fitted_period_h
        (M,) the period that fit converged to [h].
    best
        The lowest-chi-square fit of the scan.
    """

    trial_period_h: F64
    chi2: F64
    fitted_period_h: F64
    best: ConvexSolution


def scan_periods(
    model: ConvexModel,
    trial_period_h: F64,
    *,
    n_start_poles: int = N_START_POLES,
    max_iterations: int = SCAN_ITERATIONS,
    progress: bool = False,
) -> PeriodScan:
    """Chi-square against period (module doc)."""
    periods = np.asarray(trial_period_h, float)
    half = 0.5 * np.abs(np.gradient(periods)) if periods.size > 1 else np.array([np.inf])
    chi2 = np.full(periods.size, np.inf)
    fitted = np.full(periods.size, np.nan)
    best: ConvexSolution | None = None
    poles = fibonacci_poles(n_start_poles)
    with stage("period scan", total=periods.size, enabled=progress) as tick:
        for i, p in enumerate(periods):
            for lam, bet in poles:
                sol = fit_convex(model, lam, bet, p, max_iterations=max_iterations)
                if abs(sol.period_h - p) <= half[i] and sol.chi2 < chi2[i]:
                    chi2[i], fitted[i] = sol.chi2, sol.period_h
                    if best is None or sol.chi2 < best.chi2:
                        best = sol
            tick(1)
    if best is None:
        raise InputError(
            "no trial period's fit stayed within its step; widen the period range",
            field="period_range_h",
        )
    return PeriodScan(periods, chi2, fitted, best)
