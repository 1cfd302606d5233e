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
(convexinv's ``period_scan`` starts from 6) and the lowest chi-square is kept. The trials are
independent, so a long scan is shared among processes (:func:`scan_periods`).
"""

from __future__ import annotations

import os
from collections.abc import Callable
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
#: Fewest trial periods shared among processes (below, starting them costs more than it
#: saves: a worker imports speclight in about 2 s, a trial takes about 0.5 s at 1,500 points).
PARALLEL_TRIALS = 64
#: Chunks of trials per worker process (more: finer progress and load balance).
CHUNKS_PER_WORKER = 8


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


def available_cores() -> int:
    """Cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def _scan_trials(
    model: ConvexModel,
    periods: F64,
    half: F64,
    poles: F64,
    max_iterations: int,
    tick: Callable[[int], None] | None = None,
) -> tuple[F64, F64, ConvexSolution | None]:
    """Chi-square and fitted period at each trial period and the lowest fit (module doc)."""
    chi2 = np.full(periods.size, np.inf)
    fitted = np.full(periods.size, np.nan)
    best: ConvexSolution | None = None
    for i, p in enumerate(periods):
        for lam, bet in poles:
            sol = fit_convex(model, lam, bet, p, max_iterations=max_iterations)
            if abs(sol.period_h - p) <= half[i] and sol.chi2 < chi2[i]:
                chi2[i], fitted[i] = sol.chi2, sol.period_h
                if best is None or sol.chi2 < best.chi2:
                    best = sol
        if tick is not None:
            tick(1)
    return chi2, fitted, best


_WORKER: dict[str, object] = {}


def _start_worker(model: ConvexModel, poles: F64, max_iterations: int) -> None:
    """A scan worker's state; its BLAS held to one thread as in the parent (shape_run)."""
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=1, user_api="blas")
    _WORKER.update(model=model, poles=poles, max_iterations=max_iterations)


def _worker_trials(periods: F64, half: F64) -> tuple[F64, F64, ConvexSolution | None]:
    w = _WORKER
    return _scan_trials(w["model"], periods, half, w["poles"], w["max_iterations"])  # type: ignore[arg-type]


def _scan_in_processes(
    model: ConvexModel,
    periods: F64,
    half: F64,
    poles: F64,
    max_iterations: int,
    workers: int,
    tick: Callable[[int], None],
) -> tuple[F64, F64, ConvexSolution | None]:
    """:func:`_scan_trials` over ``workers`` processes, the trials in chunks (interleaved,
    so that every chunk costs about the same)."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    chi2 = np.full(periods.size, np.inf)
    fitted = np.full(periods.size, np.nan)
    best: ConvexSolution | None = None
    n_chunks = min(periods.size, CHUNKS_PER_WORKER * workers)
    chunks = [np.arange(k, periods.size, n_chunks) for k in range(n_chunks)]
    with ProcessPoolExecutor(
        max_workers=workers,
        mp_context=multiprocessing.get_context("spawn"),
        initializer=_start_worker,
        initargs=(model, poles, max_iterations),
    ) as pool:
        jobs = {pool.submit(_worker_trials, periods[c], half[c]): c for c in chunks}
        for job in as_completed(jobs):
            c = jobs[job]
            chi2[c], fitted[c], sol = job.result()
            if sol is not None and (best is None or sol.chi2 < best.chi2):
                best = sol
            tick(c.size)
    return chi2, fitted, best


def scan_periods(
    model: ConvexModel,
    trial_period_h: F64,
    *,
    n_start_poles: int = N_START_POLES,
    max_iterations: int = SCAN_ITERATIONS,
    progress: bool = False,
    workers: int | None = None,
) -> PeriodScan:
    """Chi-square against period (module doc).

    With ``workers`` > 1 (default: :func:`available_cores`) and at least
    :data:`PARALLEL_TRIALS` trial periods, the trials are shared among that many processes:
    each trial is independent, so the result is the same as in one process."""
    periods = np.asarray(trial_period_h, float)
    half = 0.5 * np.abs(np.gradient(periods)) if periods.size > 1 else np.array([np.inf])
    poles = fibonacci_poles(n_start_poles)
    n_workers = available_cores() if workers is None else workers
    if n_workers < 1:
        raise InputError(f"workers = {n_workers} must be >= 1", field="workers")
    with stage("period scan", total=periods.size, enabled=progress) as tick:
        if n_workers > 1 and periods.size >= PARALLEL_TRIALS:
            chi2, fitted, best = _scan_in_processes(
                model, periods, half, poles, max_iterations, n_workers, tick
            )
        else:
            chi2, fitted, best = _scan_trials(model, periods, half, poles, max_iterations, tick)
    if best is None:
        raise InputError(
            "no trial period's fit stayed within its step; widen the period range",
            field="period_range_h",
        )
    return PeriodScan(periods, chi2, fitted, best)
