"""Whether the data prefer another period than a fixed one (issue 25).

A search with the period fixed (the scenario's, or ``--fixed-period``) answers for that
period. Fed a wrong one it can land on another axis without a sign: on the box-wing pass of
issue 25, ``period``'s 126.864 s for a truth of 120 s gives the reversed axis (174 deg off)
with a misfit of 0.053 against 0.043 at the truth, both about 4 times the noise floor on a
coarse map, so a test of the misfit against the noise flags both. The check asks the
question that is specific to the period instead:

1. **Scan**: the periods ``P (1 + beta u)``, ``u`` in [-1, 1], ``beta`` =
   :data:`CHECK_BOUND`, around the answer's (sidereal) period ``P``, each over the whole
   coarse axis grid of the free-period scan (:mod:`.spin_axis_period_scan`: the same
   steps). A local scan at the answer's axis is not enough: there the given period is a
   local optimum (the reversed axis fits the wrong period best), the better fit lies on
   another axis.
2. **Alternative**: where the best scanned period is more than one scan step from ``P``,
   its best cell is refined (the period free within one scan step, Nelder-Mead).
3. **Test**: the per-epoch misfit differences ``d_t`` (answer minus alternative, summed
   over the bands) are correlated along the pass (the map's error, the noise), so the
   standard error of their sum is the delete-a-block jackknife's (Kuensch 1989, Ann. Stat.
   17, 1217, doi:10.1214/aos/1176347265; :data:`.spin_axis_confidence.JACKKNIFE_BLOCKS`
   blocks of consecutive epochs), ``z = sum d / se``.

**Warned** (``warn``; the axis is then not said to be constrained) where the alternative
fits better and either ``z >=`` :data:`MIN_Z` (the data prefer the other period) or its
axis lies more than :data:`.spin_axis_confidence.SECOND_REGION_DEG` from the answer (the
axis depends on the period: an error of a few percent in it moves the answer far). A
refinement of the same axis at a nearby period, fitting within the noise, is not warned.
The check is skipped where the surface is already said to be flat (the axis is not
constrained whatever the period).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.estimate.spin_axis.spin_axis_confidence import (
    FLAT_NOTE,
    JACKKNIFE_BLOCKS,
    SECOND_REGION_DEG,
    AxisConfidence,
)
from speclight.estimate.spin_axis.spin_axis_gradient import SpinMisfit
from speclight.estimate.spin_axis.spin_axis_lookup import (
    EpochGeometry,
    SpinFrameMap,
    angular_distance_deg,
)
from speclight.maps.map_lookup import ReflectivityMap

if TYPE_CHECKING:
    from speclight.estimate.spin_axis.spin_axis_ranging import RangingTerm

F64 = NDArray[np.float64]
#: Largest relative change of the period scanned (a light curve's synodic period differs
#: from the sidereal one by up to ~6 % on a low-orbit pass; :mod:`.spin_axis_period`).
CHECK_BOUND = 0.08
#: Block-jackknife z of the misfit's drop above which the data prefer the other period
#: (one-sided p ~ 0.007 for Student's t with JACKKNIFE_BLOCKS - 1 = 9 degrees of freedom).
MIN_Z = 3.0


@dataclass
class PeriodCheck:
    """What :func:`check_fixed_period` found (module doc); NaN where nothing was compared."""

    given_period_s: float = float("nan")
    preferred_period_s: float = float("nan")  # the alternative's refined period [s]
    given_misfit: float = float("nan")
    preferred_misfit: float = float("nan")
    preferred_ra_deg: float = float("nan")
    preferred_dec_deg: float = float("nan")
    separation_deg: float = float("nan")  # alternative axis from the answer [deg]
    z: float = float("nan")  # block-jackknife z of the misfit's drop
    n_periods: int = 0  # periods scanned
    warn: bool = False
    note: str = ""


def block_jackknife_z(d: F64, n_blocks: int = JACKKNIFE_BLOCKS) -> float:
    """``sum d / se`` with ``se`` the delete-a-block jackknife standard error of ``sum d``
    (``n_blocks`` runs of consecutive values; module doc); NaN with fewer values than blocks.

    Parameters
    ----------
    d
        Per-epoch values (T,) in their order along the pass.
    n_blocks
        Blocks of consecutive epochs.
    """
    d = np.asarray(d, dtype=float)
    if d.size < n_blocks or not np.all(np.isfinite(d)):
        return float("nan")
    edges = np.linspace(0, d.size, n_blocks + 1).astype(int)
    sums = np.add.reduceat(d, edges[:-1])
    # the total without each block, rescaled to all blocks: G / (G - 1) (S - s_g); the
    # jackknife variance (G - 1) / G sum (. - mean)^2 is then G / (G - 1) sum (s_g - s)^2
    g = n_blocks
    se = float(np.sqrt(g / (g - 1) * np.sum((sums - sums.mean()) ** 2)))
    return float(d.sum() / se) if se > 0 else float("inf") * np.sign(d.sum())


def per_epoch_misfit(
    bmap: ReflectivityMap,
    geo: EpochGeometry,
    y: F64,
    spin_body_axis: ArrayLike | None,
    answer: tuple[float, float, float],
    ranging: RangingTerm | None = None,
) -> F64:
    """The misfit's share of every epoch (T,) of the candidate ``answer`` (RA, Dec, phase)
    [deg] with the period ``geo.period_s`` (its sum is the misfit)."""
    model = SpinMisfit.around(bmap, geo, y, spin_body_axis, answer[0], answer[1], False, ranging)
    r, _ = model.residuals(np.array([0.0, 0.0, np.radians(answer[2])]), jacobian=False)
    return np.asarray((r**2).reshape(-1, y.shape[0], y.shape[1]).sum(axis=(0, 2)))


def check_fixed_period(
    bmap: ReflectivityMap,
    sfm: SpinFrameMap,
    geo: EpochGeometry,
    y: F64,
    spin_body_axis: ArrayLike | None,
    answer: tuple[float, float, float, float],
    coarse: tuple[F64, F64],
    terms: Callable,
    chunk: int,
    ranging: RangingTerm | None = None,
) -> PeriodCheck:
    """Scan, refine and test another period against a fixed-period answer (module doc).

    Parameters
    ----------
    bmap, sfm
        The band map and it in the spin frame (:mod:`.spin_axis_lookup`).
    geo
        Sun and observer directions and times of the epochs, with the answer's sidereal
        period [s].
    y
        Measured band light curves (T, B).
    spin_body_axis
        The spin axis in the body frame (3,), or None (+z).
    answer
        RA, Dec, phase [deg] and misfit of the answer.
    coarse
        The scan's coarse grid: RA and Dec cell centres [deg] (:func:`.spin_axis_core.radec_grid`
        at :func:`.spin_axis_period_scan.scan_grid_deg` of the search's step).
    terms
        The grid pass's sums (:func:`.spin_axis_core.grid_terms`; passed in, as
        :func:`.spin_axis_period_scan.grid_for_period` takes it, so that this module does not
        import the core that calls it).
    chunk
        Axes per lookup call (memory, not the result).
    ranging
        The range-offset term with its weight resolved, or None.
    """
    from speclight.estimate.spin_axis.spin_axis_period_scan import grid_for_period
    from speclight.estimate.spin_axis.spin_axis_refine import refine_candidate

    p0 = float(geo.period_s)
    out = PeriodCheck(given_period_s=p0, given_misfit=float(answer[3]))
    if not np.all(np.isfinite(answer)):
        out.note = "the answer is not finite: no period check"
        return out
    scan = grid_for_period(
        sfm, geo, y, *coarse, chunk, None, ranging, "sidereal", CHECK_BOUND, coarse, terms
    )
    assert scan.periods_s is not None
    out.n_periods = int(scan.periods_s.size)
    step = float(np.max(np.diff(scan.periods_s))) / p0
    if not abs(scan.period_s / p0 - 1) > step:
        out.note = f"no period within {100 * CHECK_BOUND:g} % fits better than the given one"
        return out
    ra_c, dec_c = coarse
    k = np.argmin(scan.misfit, axis=1)
    i = int(np.argmin(scan.misfit[np.arange(k.size), k]))
    start = (
        float(ra_c[i % ra_c.size]),
        float(dec_c[i // ra_c.size]),
        float(k[i]) * 360.0 / sfm.n_phases,
    )
    alt_geo = dataclasses.replace(geo, period_s=scan.period_s)
    alt = refine_candidate(
        bmap, alt_geo, y, spin_body_axis, start, 180.0 / coarse[0].size, "nelder-mead",
        step, scan.ranging, scan.period_s,
    )  # fmt: skip
    if not (np.isfinite(alt.error) and np.isfinite(alt.period_s)):
        out.note = "the other period's refinement ended at no finite misfit"
        return out
    out.preferred_period_s, out.preferred_misfit = alt.period_s, alt.error
    out.preferred_ra_deg, out.preferred_dec_deg = alt.ra_deg, alt.dec_deg
    out.separation_deg = float(angular_distance_deg(alt.ra_deg, alt.dec_deg, *answer[:2]))
    d = per_epoch_misfit(bmap, geo, y, spin_body_axis, answer[:3], ranging) - per_epoch_misfit(
        bmap,
        dataclasses.replace(geo, period_s=alt.period_s),
        y,
        spin_body_axis,
        (alt.ra_deg, alt.dec_deg, alt.phase_deg),
        ranging,
    )
    out.z = block_jackknife_z(d)
    out.warn, out.note = _verdict(out)
    return out


def _verdict(c: PeriodCheck) -> tuple[bool, str]:
    """Whether to warn, and what to say (module doc)."""
    better = c.preferred_misfit < c.given_misfit
    far = c.separation_deg > SECOND_REGION_DEG
    what = (
        f"period {c.preferred_period_s:.6g} s fits with misfit {c.preferred_misfit:.4g} "
        f"against {c.given_misfit:.4g} at the given {c.given_period_s:.6g} s (block-jackknife "
        f"z {c.z:.2g}) at RA {c.preferred_ra_deg:.1f} Dec {c.preferred_dec_deg:.1f}, "
        f"{c.separation_deg:.3g} deg from the answer"
    )
    if better and c.z >= MIN_Z:
        return True, f"the data prefer another period: {what}; the given period may be wrong"
    if better and far:
        return True, (
            f"the axis depends on the period: {what}; the given period may be wrong (free "
            "it, or check it)"
        )
    return False, f"no other period fits significantly better: {what}"


def checked_answer(
    bmap: ReflectivityMap,
    sfm: SpinFrameMap,
    geo: EpochGeometry,
    y: F64,
    spin_body_axis: ArrayLike | None,
    answer: tuple[float, float, float, float],
    coarse: tuple[F64, F64],
    terms: Callable,
    chunk: int,
    ranging: RangingTerm | None,
    confidence: AxisConfidence | None,
) -> PeriodCheck | None:
    """:func:`check_fixed_period` where the surface is not flat (None where it is, or
    without a confidence); a warning makes ``confidence`` not constrained and leads its
    note (parameters as :func:`check_fixed_period`)."""
    if confidence is None or confidence.note.startswith(FLAT_NOTE):
        return None
    check = check_fixed_period(
        bmap, sfm, geo, y, spin_body_axis, answer, coarse, terms, chunk, ranging
    )
    if check.warn:
        confidence.constrained = False
        confidence.note = f"{check.note}; {confidence.note}"
    return check
