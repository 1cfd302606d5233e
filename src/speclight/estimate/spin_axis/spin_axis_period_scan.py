"""The grid's misfit under the period as given: sidereal, synodic, or scanned when free.

* A **fixed** period: one grid pass with it as ``period_kind`` says (:mod:`.spin_axis_period`:
  ``sidereal``, ``synodic`` with each axis's own sidereal period, or ``auto``: both, the
  interpretation whose best candidate fits better kept).
* A **free** period (``period_bound = beta``): a local refinement cannot leave the basin
  of a wrong period (the rotation phase drifts by ``360 (span / P) (dP / P)`` deg over a
  pass of ``span`` seconds: 5 % off over 5 turns is 90 deg), so the periods
  ``P0 (1 + beta u)``, ``u`` in [-1, 1], are scanned first on a coarser axis grid
  (:func:`scan_grid_deg`) with a step whose drift over the pass is two phase steps; the full
  grid is then run at the period whose best candidate fits best, and the refinement starts
  there. The scan reads the period as sidereal (``synodic`` and ``auto`` are the same then:
  a synodic correction within the bound is one of the periods scanned).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.spin_axis.spin_axis_lookup import EpochGeometry, SpinFrameMap

if TYPE_CHECKING:
    from speclight.estimate.spin_axis.spin_axis_ranging import RangingTerm

F64 = NDArray[np.float64]
#: Coarsest axis grid of the period scan [deg] (the scan uses 3 grid steps up to this).
SCAN_MAX_GRID_DEG = 6.0
#: Phase drift over the pass between neighbouring periods of the scan [phase steps].
SCAN_DRIFT_STEPS = 2.0


@dataclass
class PeriodGrid:
    """What :func:`grid_for_period` found: the grid's misfit (A, K) at ``period_s``, the
    ranging term with its weight resolved, the period kind used, each kind's best misfit and,
    with a free period, the periods scanned [s] and their best misfits."""

    misfit: F64
    ranging: RangingTerm | None
    kind: str
    errors: dict[str, float]
    period_s: float
    periods_s: F64 | None = None
    period_errors: F64 | None = None


def scan_grid_deg(grid_deg: float) -> float:
    """The axis grid step of the period scan [deg]: 3 grid steps, at most
    :data:`SCAN_MAX_GRID_DEG` (never finer than the grid)."""
    return max(grid_deg, min(3 * grid_deg, SCAN_MAX_GRID_DEG))


def scan_periods(period_s: float, period_bound: float, n_phases: int, span_s: float) -> F64:
    """Periods [s] of the scan: ``P0 (1 + beta u)`` with steps whose phase drift over
    ``span_s`` is :data:`SCAN_DRIFT_STEPS` phase steps (``360 / n_phases`` deg)."""
    rel_step = SCAN_DRIFT_STEPS * period_s / (n_phases * max(span_s, period_s))
    n = int(np.ceil(2 * period_bound / rel_step)) + 1
    return period_s * (1 + period_bound * np.linspace(-1.0, 1.0, max(n, 3)))


def grid_for_period(
    sfm: SpinFrameMap,
    geo: EpochGeometry,
    y: F64,
    ra: F64,
    dec: F64,
    chunk: int,
    progress: Callable[[int, int], None] | None,
    ranging: RangingTerm | None,
    period_kind: str,
    period_bound: float | None,
    coarse: tuple[F64, F64],
    terms: Callable[..., tuple[F64, F64 | None]],
) -> PeriodGrid:
    """The grid's misfit under the period as given (module doc).

    Parameters
    ----------
    sfm, geo, y, ra, dec, chunk, progress, ranging
        As :func:`.spin_axis_core.grid_terms`.
    period_kind
        ``sidereal``, ``synodic`` or ``auto`` (:mod:`.spin_axis_period`).
    period_bound
        None: the period ``geo.period_s`` is fixed; else the fraction within which it is
        scanned.
    coarse
        The scan's RA and Dec cell centres [deg] (a grid of :func:`scan_grid_deg`).
    terms
        :func:`.spin_axis_core.grid_terms` (passed in: the core calls this module).
    """
    import dataclasses

    if period_bound is None:
        kinds = ["sidereal", "synodic"] if period_kind == "auto" else [period_kind]
        found = {
            k: _one_pass(terms, sfm, geo, y, ra, dec, chunk, progress, ranging, k) for k in kinds
        }
        errors = {k: _best(v[0]) for k, v in found.items()}
        kind = min(kinds, key=lambda k: errors[k])
        return PeriodGrid(found[kind][0], found[kind][1], kind, errors, geo.period_s)
    ra_c, dec_c = coarse
    span = float(np.ptp(geo.t_s)) if geo.t_s.size else 0.0
    periods = scan_periods(geo.period_s, period_bound, sfm.n_phases, span)
    scanned = np.array(
        [
            _best(
                _one_pass(
                    terms, sfm, dataclasses.replace(geo, period_s=float(p)), y, ra_c, dec_c, chunk,
                    None, ranging, "sidereal",
                )[0]
            )
            for p in periods
        ]
    )  # fmt: skip
    p_best = (
        float(periods[int(np.argmin(scanned))]) if np.any(np.isfinite(scanned)) else geo.period_s
    )
    flat, rg = _one_pass(
        terms, sfm, dataclasses.replace(geo, period_s=p_best), y, ra, dec, chunk, progress, ranging,
        "sidereal",
    )  # fmt: skip
    return PeriodGrid(flat, rg, "sidereal", {"sidereal": _best(flat)}, p_best, periods, scanned)


def _best(flat: F64) -> float:
    return float(np.min(flat)) if np.any(np.isfinite(flat)) else float("inf")


def _one_pass(
    terms: Callable[..., tuple[F64, F64 | None]],
    sfm: SpinFrameMap,
    geo: EpochGeometry,
    y: F64,
    ra: F64,
    dec: F64,
    chunk: int,
    progress: Callable[[int, int], None] | None,
    ranging: RangingTerm | None,
    kind: str,
) -> tuple[F64, RangingTerm | None]:
    """One grid pass (A, K) with ``geo.period_s`` read as ``kind``, and the ranging term
    with its weight resolved."""
    from speclight.estimate.spin_axis.spin_axis_period import bisector_rates, sidereal_periods

    periods = None
    if kind == "synodic":
        dd, rr = np.meshgrid(dec, ra, indexing="ij")
        periods = sidereal_periods(geo.period_s, bisector_rates(geo, rr.ravel(), dd.ravel()))
    flat, e_r = terms(sfm, geo, y, ra, dec, chunk, progress, ranging, periods)
    if ranging is not None and e_r is not None:
        from speclight.estimate.spin_axis.spin_axis_ranging import resolve_weight

        ranging = resolve_weight(ranging, flat, e_r)
        flat = flat + float(ranging.weight or 0.0) * e_r
    return flat, ranging
