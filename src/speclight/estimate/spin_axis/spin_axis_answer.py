"""From the grid's best and mirror cells to the answer: the refinement, with a synodic period
kept consistent with the axis, and the fallback to the best cell (definitions in
:mod:`.spin_axis_core`).

With a synodic period (:mod:`.spin_axis_period`) every axis has its own sidereal period. A
refinement with the period fixed then alternates: refine the axis and phase with the
sidereal period of the current axis, recompute that period for the new axis, until the
period changes by less than :data:`PERIOD_RTOL` (at most :data:`MAX_ROUNDS` rounds; the
grid gave each axis its own period, so the first round starts close). With a free period the
refinement fits the period itself, around the sidereal period of the start axis.
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.estimate.spin_axis.spin_axis_lookup import EpochGeometry
from speclight.estimate.spin_axis.spin_axis_misfit import exact_misfit
from speclight.estimate.spin_axis.spin_axis_period import axis_sidereal_period
from speclight.maps.map_lookup import ReflectivityMap

if TYPE_CHECKING:
    from speclight.estimate.spin_axis.spin_axis_ranging import RangingTerm
    from speclight.estimate.spin_axis.spin_axis_refine import Refined

F64 = NDArray[np.float64]
Answer = tuple[float, float, float, float]
#: Relative change of the sidereal period that ends the alternation.
PERIOD_RTOL = 1e-6
#: Most rounds of the alternation.
MAX_ROUNDS = 6


def axis_geometry(
    geo: EpochGeometry, synodic_s: float | None, ra: float, dec: float
) -> EpochGeometry:
    """``geo`` with the sidereal period of the axis (RA, Dec) [deg] for the synodic period
    ``synodic_s`` [s]; ``geo`` itself where the period is sidereal (None)."""
    if synodic_s is None:
        return geo
    return dataclasses.replace(geo, period_s=axis_sidereal_period(geo, synodic_s, ra, dec))


def refine_start(
    bmap: ReflectivityMap,
    geo: EpochGeometry,
    y: F64,
    spin_body_axis: ArrayLike | None,
    start: Answer,
    step_deg: float,
    method: str,
    period_bound: float | None,
    ranging: RangingTerm | None,
    synodic_s: float | None,
    start_period_s: float | None = None,
) -> Refined:
    """One start refined (module doc); the evaluations of every round are counted;
    ``start_period_s``: where a free period starts [s] (default the bound's centre)."""
    from speclight.estimate.spin_axis.spin_axis_refine import Refined, refine_candidate

    g = axis_geometry(geo, synodic_s, start[0], start[1])
    if not np.isfinite(g.period_s):
        return Refined(*(float("nan"),) * 5, 0, 0)
    got = refine_candidate(
        bmap, g, y, spin_body_axis, start[:3], step_deg, method, period_bound, ranging,
        start_period_s,
    )  # fmt: skip
    if synodic_s is None or period_bound is not None:
        return got
    n_m, n_g = got.n_misfit, got.n_gradient
    for _ in range(MAX_ROUNDS - 1):
        g_new = axis_geometry(geo, synodic_s, got.ra_deg, got.dec_deg)
        if not np.isfinite(g_new.period_s):
            break
        if abs(g_new.period_s - g.period_s) <= PERIOD_RTOL * g.period_s:
            break
        g = g_new
        got = refine_candidate(
            bmap, g, y, spin_body_axis, got.answer[:3], step_deg / 4, method, None, ranging
        )
        n_m, n_g = n_m + got.n_misfit, n_g + got.n_gradient
    return dataclasses.replace(got, n_misfit=n_m, n_gradient=n_g)


def refined_or_best(
    tries: list[Refined], best: Answer, best_exact: float, best_period_s: float
) -> tuple[Answer, float, str]:
    """The best finite refinement (answer, period [s], "") of ``tries``; the grid's best
    cell with its misfit under the map's own interpolation, its period and the reason,
    where no refinement ended finite or none below that misfit."""
    finite = [t for t in tries if np.all(np.isfinite(t.answer)) and np.isfinite(t.period_s)]
    exact = float(best_exact) if np.isfinite(best_exact) else best[3]
    fallback = (best[0], best[1], best[2], exact)
    if not finite:
        return (
            fallback,
            best_period_s,
            (
                "the refinement ended at no finite misfit from any start; refined_* is the "
                "grid's best cell"
            ),
        )
    chosen = min(finite, key=lambda t: t.error)
    if np.isfinite(best_exact) and chosen.error > best_exact:
        return (
            fallback,
            best_period_s,
            (
                f"the refinement ended at a misfit {chosen.error:.4g} above the grid's best "
                f"cell's {best_exact:.4g}; refined_* is that cell"
            ),
        )
    return chosen.answer, chosen.period_s, ""


def refine_answer(
    bmap: ReflectivityMap,
    geo: EpochGeometry,
    y: F64,
    spin_body_axis: ArrayLike | None,
    starts: list[Answer],
    step_deg: float,
    method: str,
    period_bound: float | None,
    ranging: RangingTerm | None,
    synodic_s: float | None,
    start_period_s: float | None = None,
) -> tuple[Answer, float, str, int, int]:
    """Refine every start (best first) and choose: (answer, period [s], note, misfit and
    gradient evaluations)."""
    tries = [
        refine_start(
            bmap,
            geo,
            y,
            spin_body_axis,
            s,
            step_deg,
            method,
            period_bound,
            ranging,
            synodic_s,
            start_period_s,
        )
        for s in starts
    ]
    best = starts[0]
    g_best = axis_geometry(geo, synodic_s, best[0], best[1])
    if start_period_s is not None:  # a free period: the best cell's is the scan's
        g_best = dataclasses.replace(geo, period_s=float(start_period_s))
    best_exact = exact_misfit(bmap, g_best, y, spin_body_axis, *best[:3], ranging)
    answer, period, note = refined_or_best(tries, best, best_exact, g_best.period_s)
    return (
        answer,
        period,
        note,
        sum(t.n_misfit for t in tries),
        sum(t.n_gradient for t in tries),
    )


#: A free period within this fraction of ``period_bound`` from its edge is "at the edge".
EDGE_FRACTION = 0.02


def period_edge_note(
    geo: EpochGeometry,
    synodic_s: float | None,
    answer: Answer,
    period_s: float,
    period_bound: float | None,
) -> str:
    """A note where a free period ended at the edge of ``[P0 (1 - b), P0 (1 + b)]`` (the
    truth may lie beyond it: the answer is then the bound's, not the data's), else ``""``.

    ``P0`` is the sidereal period the refinement started from at the answer's axis
    (:func:`axis_geometry`), ``b`` is ``period_bound``.
    """
    if period_bound is None or not np.isfinite(period_s) or not np.isfinite(answer[0]):
        return ""
    p0 = axis_geometry(geo, synodic_s, answer[0], answer[1]).period_s
    if not np.isfinite(p0) or p0 <= 0:
        return ""
    rel = period_s / p0 - 1.0
    if abs(rel) < period_bound * (1.0 - EDGE_FRACTION):
        return ""
    side = "upper" if rel > 0 else "lower"
    return (
        f"the free period ended at the {side} edge of its range ({period_s:.6g} s, "
        f"{100 * rel:+.2f} % of {p0:.6g} s; period_bound {period_bound:g}): the data may "
        "prefer a period beyond it, so the axis and the period are the bound's answer; "
        "widen the bound or give a better period"
    )
