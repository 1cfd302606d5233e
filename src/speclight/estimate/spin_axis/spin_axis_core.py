"""Spin-axis grid search against a reflectivity map (Nussbaum et al. 2022, section 5.3, Fig. 18).

The target spins about a known body axis with a known period; unknown are the spin axis in
GCRS (RA, Dec) and the rotation phase at the scenario start. For every axis of an RA/Dec
grid and every one of ``n_phases`` phases the band light curves are predicted from the map
(:mod:`.spin_axis_lookup`) and compared with the measured ones.

**Normalisation** (the reference normalises count rates before the least squares, without
saying how): each band's light curve, measured and predicted, is divided by its mean over
the epochs used, so unknown per-band scales (albedo, aperture, calibration) drop out and the
bands weigh alike. The measured light curves are band reflectance factors (eq. 5 of the
reference), which the range, the atmosphere and the Sun's distance do not change; the map's
band rates are proportional to them. **Misfit**: the mean over epochs and bands of the
squared difference of the normalised curves; ``error(ra, dec)`` is its minimum over the
phase. Epochs where a band is not measured (NaN) are left out. With ranging returns
(:mod:`.spin_axis_ranging`) the misfit adds ``weight x`` the ranging term.

The **mirror** solution is the lowest local minimum of ``error`` (8 neighbours, RA
periodic) farther than ``mirror_sep_deg`` from the best cell: for a body symmetric about
its equatorial plane, the reversed axis with the phase that swaps the halves fits as well.
**Refinement** (:mod:`.spin_axis_refine`): Nelder-Mead (scipy) over (RA, Dec, phase) on
the same misfit with the map's own interpolation (HEALPix bilinear, no grid), from the best
and the mirror cells; or L-BFGS-B / least squares with the analytic gradient
(:mod:`.spin_axis_gradient`), or SLSQP with finite differences; optionally with the period
free within a bound.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError
from speclight.estimate.spin_axis.spin_axis_grid import misfit_from_sums as misfit_from_sums
from speclight.estimate.spin_axis.spin_axis_lookup import (
    EpochGeometry,
    SpinFrameMap,
)
from speclight.estimate.spin_axis.spin_axis_lookup import (
    angular_distance_deg as angular_distance_deg,
)
from speclight.estimate.spin_axis.spin_axis_misfit import exact_misfit as exact_misfit
from speclight.maps.map_lookup import ReflectivityMap

if TYPE_CHECKING:
    from speclight.estimate.spin_axis.spin_axis_confidence import AxisConfidence
    from speclight.estimate.spin_axis.spin_axis_period_check import PeriodCheck
    from speclight.estimate.spin_axis.spin_axis_ranging import RangingTerm

F64 = NDArray[np.float64]
#: Axes per chunk of the grid search whose lookup indices are computed in one call (memory
#: ~ chunk x epochs x 0.5 kB; the gathers and sums run in smaller blocks within a chunk).
DEFAULT_AXIS_CHUNK = 256
#: A second minimum must lie this far from the best cell to count as the mirror [deg].
MIRROR_SEP_DEG = 20.0
#: Finest grid and phase step accepted [deg]: 36", far finer than the pixels of any map
#: (0.23 deg at HEALPix nside 256); how large a search may be is estimated apart
#: (:mod:`.spin_axis_limits`).
MIN_STEP_DEG = 0.01


@dataclass
class SpinAxisResult:
    """What :func:`spin_axis_search` found (angles in degrees, GCRS)."""

    ra_deg: F64
    dec_deg: F64
    error: F64  # (ra, dec)
    best_phase_deg: F64  # (ra, dec)
    phase_deg: F64  # (n_phases,)
    best: tuple[float, float, float, float]  # ra, dec, phase, error
    mirror: tuple[float, float, float, float]
    refined: tuple[float, float, float, float]
    n_epochs: int
    band_names: list[str]
    ranging_weight: float = 0.0  # the weight used (0: no ranging term)
    refine_method: str = "nelder-mead"
    refined_period_s: float = float("nan")  # the period of ``refined`` [s]
    refine_n_misfit: int = 0  # misfit evaluations of the refinement (all starts)
    refine_n_gradient: int = 0  # analytic gradient (Jacobian) evaluations
    #: what became of the refinement, in words ("" where it ended below the grid's best)
    refine_note: str = ""
    #: how the given period was read (``sidereal`` or ``synodic``; :mod:`.spin_axis_period`)
    period_kind: str = "sidereal"
    #: the grid's best misfit under each period kind tried
    period_kind_errors: dict[str, float] = field(default_factory=dict)
    #: sigmas, regions and flags of the refined solution (None without a refinement)
    confidence: AxisConfidence | None = None
    #: with a free period: the periods scanned [s] and the best misfit of each
    scan_periods_s: F64 | None = None
    scan_errors: F64 | None = None
    #: with a fixed period: whether another period fits better (:mod:`.spin_axis_period_check`)
    period_check: PeriodCheck | None = None


def check_search_options(grid_deg: float, n_phases: int) -> None:
    """Refuse a grid or phase step outside [MIN_STEP_DEG, 90] deg (how large a search
    may be: :func:`.spin_axis_limits.check_search_cost`)."""
    if not (np.isfinite(grid_deg) and MIN_STEP_DEG <= grid_deg <= 90):
        raise InputError(
            f"grid_deg = {grid_deg} must be in [{MIN_STEP_DEG:g}, 90] [deg] (no map resolves "
            "a finer step)",
            field="grid_deg",
        )
    if not 1 <= int(n_phases) <= round(360 / MIN_STEP_DEG):
        raise InputError(
            f"n_phases = {n_phases} must be 1..{round(360 / MIN_STEP_DEG)} (a phase step of at "
            f"least {MIN_STEP_DEG:g} deg)",
            field="n_phases",
        )


def check_measured_curves(y: F64, band_names: list[str]) -> None:
    """Refuse a band whose measured curve (T, B) cannot be divided by its mean: a mean that
    is not > 0 (all zero, negative or no light), or no finite value at all."""
    with np.errstate(invalid="ignore"):
        mean = np.mean(y, axis=0)
    bad = [j for j in range(y.shape[1]) if not mean[j] > 0 or not np.isfinite(mean[j])]
    if bad:
        shown = ", ".join(f"'{band_names[j]}' ({mean[j]:.3g})" for j in bad)
        raise InputError(
            f"the measured curve of band(s) {shown} has a mean over the {y.shape[0]} usable "
            "epochs that is not > 0: it cannot be divided by its mean (all zero, negative "
            "or no light in that band); leave it out: bands = the others",
            field="y",
        )


def radec_grid(grid_deg: float) -> tuple[F64, F64]:
    """Cell centres: RA ``0, D, 2D, ...`` below 360 and Dec ``-90 + D/2, ..., 90 - D/2``."""
    n_ra = max(1, round(360.0 / grid_deg))
    n_dec = max(1, round(180.0 / grid_deg))
    return np.arange(n_ra) * 360.0 / n_ra, -90.0 + (np.arange(n_dec) + 0.5) * 180.0 / n_dec


def normalised(y: F64) -> F64:
    """Each band (column) divided by its mean over the epochs (rows)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        return y / np.mean(y, axis=0)


def grid_errors(
    sfm: SpinFrameMap,
    geo: EpochGeometry,
    y: F64,
    ra_deg: F64,
    dec_deg: F64,
    chunk: int = DEFAULT_AXIS_CHUNK,
    progress: Callable[[int, int], None] | None = None,
    ranging: RangingTerm | None = None,
    period_s_axes: F64 | None = None,
) -> tuple[F64, NDArray[np.int64]]:
    """Misfit (A, n_phases) of every axis of the RA x Dec grid (A = n_ra n_dec, RA fastest)
    and the best phase's index per axis.

    Parameters
    ----------
    sfm
        The map in the spin frame (:func:`.spin_axis_lookup.spin_frame_map`).
    geo
        Sun and observer directions and times of the epochs.
    y
        Measured band light curves (T, B).
    ra_deg, dec_deg
        The grid's RA and Dec values [deg].
    chunk
        Axes per lookup call (memory, not the result).
    progress
        Called with (done, total) axes, or None.
    ranging
        The range-offset term, or None.
    period_s_axes
        Each axis's own period [s] (n_dec n_ra,), or None for ``geo.period_s``.
    """
    e_i, e_r = grid_terms(sfm, geo, y, ra_deg, dec_deg, chunk, progress, ranging, period_s_axes)
    out = e_i if e_r is None or ranging is None else e_i + float(ranging.weight or 0.0) * e_r
    return out, np.argmin(out, axis=1)


def grid_terms(
    sfm: SpinFrameMap,
    geo: EpochGeometry,
    y: F64,
    ra_deg: F64,
    dec_deg: F64,
    chunk: int = DEFAULT_AXIS_CHUNK,
    progress: Callable[[int, int], None] | None = None,
    ranging: RangingTerm | None = None,
    period_s_axes: F64 | None = None,
) -> tuple[F64, F64 | None]:
    """Intensity term (A, n_phases) and ranging term (or None) of every grid candidate
    (:func:`.spin_axis_grid.grid_pass`).

    Parameters
    ----------
    sfm
        The map in the spin frame (:func:`.spin_axis_lookup.spin_frame_map`).
    geo
        Sun and observer directions and times of the epochs.
    y
        Measured band light curves (T, B).
    ra_deg, dec_deg
        The grid's RA and Dec values [deg].
    chunk
        Axes per lookup call (memory, not the result).
    progress
        Called with (done, total) axes, or None.
    ranging
        The range-offset term, or None.
    period_s_axes
        Each axis's own period [s] (n_dec n_ra,), or None for ``geo.period_s``.
    """
    from speclight.estimate.spin_axis.spin_axis_grid import grid_pass

    dd, rr = np.meshgrid(dec_deg, ra_deg, indexing="ij")
    return grid_pass(
        sfm, geo, y, rr.ravel(), dd.ravel(), chunk, progress, ranging,
        period_s_axes=period_s_axes,
    )  # fmt: skip


def local_minima(error: F64) -> NDArray[np.int64]:
    """Flat indices of cells of ``error`` (dec, ra) no larger than their 8 neighbours and
    smaller than one of them (RA periodic, Dec not), sorted by error."""
    e = np.where(np.isfinite(error), error, np.inf)
    padded = np.pad(e, ((1, 1), (0, 0)), constant_values=np.nan)  # beyond the poles: none
    ok = np.ones(e.shape, dtype=bool)
    below_one = np.zeros(e.shape, dtype=bool)  # a plateau is no minimum
    for di in (-1, 0, 1):
        for dj in (-1, 0, 1):
            if di == 0 and dj == 0:
                continue
            shifted = np.roll(padded, (-di, -dj), axis=(0, 1))[1:-1]
            with np.errstate(invalid="ignore"):
                ok &= ~(shifted < e)
                below_one |= e < shifted
    idx = np.flatnonzero(ok & below_one & np.isfinite(e))
    return idx[np.argsort(e.ravel()[idx], kind="stable")]


def spin_axis_search(
    bmap: ReflectivityMap,
    sfm: SpinFrameMap,
    geo: EpochGeometry,
    y: F64,
    band_names: list[str],
    grid_deg: float,
    spin_body_axis: ArrayLike | None = None,
    chunk: int = DEFAULT_AXIS_CHUNK,
    progress: Callable[[int, int], None] | None = None,
    do_refine: bool = True,
    ranging: RangingTerm | None = None,
    refine_method: str = "nelder-mead",
    period_bound: float | None = None,
    period_kind: str = "sidereal",
    period_check: bool = True,
) -> SpinAxisResult:
    """Grid search, mirror and refinement (module docstring).

    Parameters
    ----------
    bmap
        The band map (:func:`.spin_axis_lookup.load_band_map`).
    sfm
        ``bmap`` resampled on the spin frame of ``spin_body_axis``
        (:func:`.spin_axis_lookup.spin_frame_map`); its ``n_phases`` are the phases tried.
    geo
        Inertial Sun and observer directions of the epochs, their times and the period.
    y
        (T, B) measured band reflectance factors (or rates free of range and atmosphere).
    ranging
        Measured range offsets (T, B) with their map and weight, or None.
    grid_deg
        RA/Dec grid step [deg], in (0, 90].
    refine_method
        :data:`.spin_axis_refine.REFINE_METHODS`.
    period_bound
        None: the period ``geo.period_s`` is fixed; else the refinement fits it too, within
        this fraction of it.
    period_kind
        What ``geo.period_s`` is (:mod:`.spin_axis_period`): ``sidereal`` (the body's),
        ``synodic`` (the light curve's: each axis gets its own sidereal period) or ``auto``
        (both tried, the better fit kept).
    period_check
        With a fixed period and a refinement: scan the periods around it and warn where the
        data prefer another (:mod:`.spin_axis_period_check`).
    """
    from speclight.estimate.spin_axis.spin_axis_period import check_period_kind
    from speclight.estimate.spin_axis.spin_axis_refine import check_refine_options

    check_search_options(grid_deg, sfm.n_phases)
    check_refine_options(refine_method, period_bound)
    check_period_kind(period_kind)
    ok = np.all(np.isfinite(y), axis=1)
    ok &= np.all(np.isfinite(geo.sun_gcrs), axis=1) & np.all(np.isfinite(geo.observer_gcrs), axis=1)
    if ok.sum() < 3:
        raise InputError(
            f"only {int(ok.sum())} epochs have every band measured and a known geometry; the "
            "search needs at least 3",
            field="MEASURED",
        )
    geo = EpochGeometry(geo.sun_gcrs[ok], geo.observer_gcrs[ok], geo.t_s[ok], geo.period_s)
    y = np.asarray(y, dtype=float)[ok]
    check_measured_curves(y, band_names)
    ranging = ranging.select(ok) if ranging is not None else None
    ra, dec = radec_grid(grid_deg)
    from speclight.estimate.spin_axis.spin_axis_period_scan import grid_for_period, scan_grid_deg

    coarse = radec_grid(scan_grid_deg(grid_deg))  # the period scans' grid (both of them)
    scan = grid_for_period(
        sfm, geo, y, ra, dec, chunk, progress, ranging, period_kind, period_bound, coarse,
        grid_terms,
    )  # fmt: skip
    flat, ranging, kind = scan.misfit, scan.ranging, scan.kind
    if not np.any(np.isfinite(flat)):
        raise InputError(
            f"no candidate of the grid has a finite misfit: at the {int(ok.sum())} measured "
            "epochs the map predicts no light (a band's mean rate is 0) in some band for "
            "every spin axis and phase; check that the map is of this target, with these "
            "bands, and covers the pass's phase angles",
            field="bmap",
        )
    synodic_s = geo.period_s if kind == "synodic" else None
    start_period_s = scan.period_s if period_bound is not None else None
    best_k = np.argmin(flat, axis=1)
    phase = np.arange(sfm.n_phases) * 360.0 / sfm.n_phases
    error = flat.min(axis=1).reshape(dec.size, ra.size)
    best_phase = phase[best_k].reshape(dec.size, ra.size)
    minima = local_minima(error)
    i_best = int(minima[0]) if minima.size else int(np.argmin(error))
    rr, dd = np.meshgrid(ra, dec)
    r_f, d_f, p_f, e_f = rr.ravel(), dd.ravel(), best_phase.ravel(), error.ravel()
    best = (float(r_f[i_best]), float(d_f[i_best]), float(p_f[i_best]), float(e_f[i_best]))
    far = minima[angular_distance_deg(r_f[minima], d_f[minima], best[0], best[1]) > MIRROR_SEP_DEG]
    nan4 = (np.nan, np.nan, np.nan, np.nan)
    mirror = nan4
    if far.size:
        i = int(far[0])
        mirror = (float(r_f[i]), float(d_f[i]), float(p_f[i]), float(e_f[i]))
    refined = nan4
    n_m = n_g = 0
    note = "not refined (the refinement was turned off): refined_* is NaN"
    period_s = float("nan")
    confidence = None
    if do_refine:
        from speclight.estimate.spin_axis.spin_axis_answer import period_edge_note, refine_answer
        from speclight.estimate.spin_axis.spin_axis_confidence import axis_confidence, with_period

        step = max(grid_deg, 360.0 / sfm.n_phases) / 2
        starts = [best] + ([mirror] if far.size else [])
        refined, period_s, note, n_m, n_g = refine_answer(
            bmap, geo, y, spin_body_axis, starts, step, refine_method, period_bound, ranging,
            synodic_s, start_period_s,
        )  # fmt: skip
        confidence = axis_confidence(
            bmap, with_period(geo, period_s), y, spin_body_axis, refined, error, dec, ra,
            period_bound is not None, ranging,
        )  # fmt: skip
        edge = period_edge_note(geo, synodic_s, refined, period_s, period_bound)
        if edge and confidence is not None:
            confidence.constrained = False
            confidence.note = f"{edge}; {confidence.note}"
    checked = None
    if do_refine and period_check and period_bound is None:
        from speclight.estimate.spin_axis.spin_axis_period_check import checked_answer

        checked = checked_answer(
            bmap, sfm, with_period(geo, period_s), y, spin_body_axis, refined,
            coarse, grid_terms, chunk, ranging, confidence,
        )  # fmt: skip
    return SpinAxisResult(
        ra,
        dec,
        error.T.copy(),
        best_phase.T.copy(),
        phase,
        best,
        mirror,
        refined,
        int(ok.sum()),
        list(band_names),
        0.0 if ranging is None else float(ranging.weight or 0.0),
        refine_method,
        period_s,
        n_m,
        n_g,
        note,
        kind,
        scan.errors,
        confidence,
        scan.periods_s,
        scan.period_errors,
        checked,
    )
