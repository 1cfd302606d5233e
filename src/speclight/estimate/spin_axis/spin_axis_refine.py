"""Local refinement of a spin-axis candidate: Nelder-Mead, gradient-based, or SLSQP.

All methods minimise the same misfit (:func:`.spin_axis_misfit.exact_misfit`: the map's own
interpolation, no spin-frame grid) from a start (RA, Dec, phase), with the period fixed or,
with ``period_bound = beta``, free within ``[P0 (1 - beta), P0 (1 + beta)]``:

* ``nelder-mead`` (scipy): over (RA, Dec, phase) [deg] (and, with a free period, the extra
  rotation over the pass ``f`` [deg], :mod:`.spin_axis_gradient`), an initial simplex of
  ``step`` deg; misfit only.
* ``gradient``: L-BFGS-B (scipy) over the parameters ``x`` of :mod:`.spin_axis_gradient`
  (tangent rotation vector of the axis, phase, ``f``) with the analytic gradient.
* ``gradient-continuation``: ``gradient`` on the map degraded to HEALPix ``nside`` 2, 4,
  ... up to half the map's (:mod:`.spin_axis_continuation`), each stage from where the
  last ended, then on the real map: a larger basin (docs/spin-axis.md) for 2-3 times the
  evaluations near the optimum.
* ``gauss-newton``: scipy ``least_squares`` (trust-region reflective) on the residuals with
  their analytic Jacobian.
* ``slsqp``: SLSQP (scipy) over the same ``x`` with gradients from scipy's forward finite
  differences (the comparison method of issue 15: "SLSQP with numerical Jacobians").

The evaluations are counted: ``n_misfit`` misfit (or residual) evaluations, including those
finite differences spend, and ``n_gradient`` analytic gradient (or Jacobian) evaluations,
each of which also gives the misfit and costs about 2-3 misfit evaluations.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError
from speclight.estimate.spin_axis.spin_axis_continuation import (
    Stage,
    continuation_stages,
    stage_model,
)
from speclight.estimate.spin_axis.spin_axis_gradient import SpinMisfit
from speclight.estimate.spin_axis.spin_axis_lookup import EpochGeometry
from speclight.maps.map_lookup import ReflectivityMap

if TYPE_CHECKING:
    from speclight.estimate.spin_axis.spin_axis_ranging import RangingTerm

F64 = NDArray[np.float64]
REFINE_METHODS = ("nelder-mead", "gradient", "gradient-continuation", "gauss-newton", "slsqp")
#: Iteration limits (Nelder-Mead: its 400 of before; the others converge in far fewer;
#: ``gradient-continuation``: ``gradient``'s per stage).
MAX_ITER = {"nelder-mead": 400, "gradient": 200, "gauss-newton": 200, "slsqp": 200}


@dataclass(frozen=True)
class Refined:
    """A refined candidate: angles [deg], misfit, period [s] and the evaluations spent."""

    ra_deg: float
    dec_deg: float
    phase_deg: float
    error: float
    period_s: float
    n_misfit: int
    n_gradient: int

    @property
    def answer(self) -> tuple[float, float, float, float]:
        return self.ra_deg, self.dec_deg, self.phase_deg, self.error


def check_refine_options(method: str, period_bound: float | None) -> None:
    """Refuse an unknown method or a period bound outside (0, 0.5)."""
    if method not in REFINE_METHODS:
        raise InputError(
            f"refine_method = {method!r}; accepted: {', '.join(REFINE_METHODS)}",
            field="refine_method",
        )
    if period_bound is not None and not (np.isfinite(period_bound) and 0 < period_bound < 0.5):
        raise InputError(
            f"period_bound = {period_bound} must be in (0, 0.5) (a fraction of the period)",
            field="period_bound",
        )


@dataclass
class _Counter:
    misfit: int = 0
    gradient: int = 0


def refine_candidate(
    bmap: ReflectivityMap,
    geo: EpochGeometry,
    y: F64,
    spin_body_axis: ArrayLike | None,
    start: tuple[float, float, float],
    step_deg: float,
    method: str = "nelder-mead",
    period_bound: float | None = None,
    ranging: RangingTerm | None = None,
    start_period_s: float | None = None,
) -> Refined:
    """Refine ``start`` (RA, Dec, phase) [deg] with ``method`` (module docstring).

    Parameters
    ----------
    bmap
        The band map.
    geo
        Sun and observer directions and times of the epochs.
    y
        Measured band light curves (T, B).
    spin_body_axis
        The spin axis in the body frame (3,), or None (+z).
    start
        The candidate (RA, Dec, phase) [deg] to refine.
    step_deg
        The grid step [deg] (the initial simplex's size).
    method
        ``nelder-mead``, ``gradient``, ``gradient-continuation``, ``gauss-newton`` or
        ``slsqp``.
    period_bound
        None for the period ``geo.period_s`` fixed, else the fraction of it by which the
        fitted period may differ.
    ranging
        The range-offset term, or None.
    start_period_s
        Where the period starts [s] (default ``geo.period_s``, the centre of the bound).
    """
    check_refine_options(method, period_bound)
    model, x0, bounds = _setup(
        bmap, geo, y, spin_body_axis, start, period_bound, ranging, start_period_s
    )
    count = _Counter()
    if method == "nelder-mead":
        return _nelder_mead(model, spin_body_axis, start, x0, bounds, step_deg, count)
    if method == "gradient-continuation":
        return _staged(model, x0, bounds, continuation_stages(bmap.header.nside), count)
    x = _minimise(model, x0, bounds, method, count)
    ra, dec, phase, period = model.to_spin_model(x)
    return Refined(ra, dec, phase, model.misfit(x), period, count.misfit, count.gradient)


def refine_staged(
    bmap: ReflectivityMap,
    geo: EpochGeometry,
    y: F64,
    spin_body_axis: ArrayLike | None,
    start: tuple[float, float, float],
    stages: Sequence[Stage],
    period_bound: float | None = None,
    ranging: RangingTerm | None = None,
    start_period_s: float | None = None,
) -> Refined:
    """The ``gradient`` refinement run on each of ``stages`` in turn
    (:mod:`.spin_axis_continuation`), each from where the last ended, then on the real
    misfit; the evaluations of all stages are counted.

    Parameters
    ----------
    bmap
        The band map.
    geo
        Sun and observer directions and times of the epochs.
    y
        Measured band light curves (T, B).
    spin_body_axis
        The spin axis in the body frame (3,), or None (+z).
    start
        The candidate (RA, Dec, phase) [deg] to refine.
    stages
        The coarsened misfits, coarsest first.
    period_bound
        None for a fixed period, else the fraction by which the period may differ.
    ranging
        The range-offset term, or None.
    start_period_s
        Where the period starts [s] (default ``geo.period_s``).
    """
    check_refine_options("gradient", period_bound)
    model, x, bounds = _setup(
        bmap, geo, y, spin_body_axis, start, period_bound, ranging, start_period_s
    )
    return _staged(model, x, bounds, stages, _Counter())


def _staged(
    model: SpinMisfit, x: F64, bounds: list, stages: Sequence[Stage], count: _Counter
) -> Refined:
    for stage in stages:
        x = _minimise(stage_model(model, stage), x, bounds, "gradient", count)
    x = _minimise(model, x, bounds, "gradient", count)
    ra, dec, phase, period = model.to_spin_model(x)
    return Refined(ra, dec, phase, model.misfit(x), period, count.misfit, count.gradient)


def _setup(
    bmap: ReflectivityMap,
    geo: EpochGeometry,
    y: F64,
    spin_body_axis: ArrayLike | None,
    start: tuple[float, float, float],
    period_bound: float | None,
    ranging: RangingTerm | None,
    start_period_s: float | None,
) -> tuple[SpinMisfit, F64, list]:
    """The misfit around ``start``, the start ``x0`` and the bounds of ``x``."""
    free = period_bound is not None
    model = SpinMisfit.around(bmap, geo, y, spin_body_axis, start[0], start[1], free, ranging)
    x0 = [0.0, 0.0, float(np.radians(start[2]))]
    bounds: list = [(-np.pi, np.pi), (-np.pi, np.pi), (None, None)]
    if free:
        assert period_bound is not None
        p0 = geo.period_s
        lo, hi = (
            model.f_for_period(p0 * (1 + period_bound)),
            model.f_for_period(p0 * (1 - period_bound)),
        )
        x0.append(model.f_for_period(start_period_s) if start_period_s else 0.0)
        bounds.append((lo, hi))
    return model, np.asarray(x0), bounds


def _minimise(model: SpinMisfit, x0: F64, bounds: list, method: str, count: _Counter) -> F64:
    from scipy.optimize import least_squares, minimize

    def fun(x: F64) -> float:
        count.misfit += 1
        return model.misfit(x)

    def fun_grad(x: F64) -> tuple[float, F64]:
        count.gradient += 1
        return model.misfit_and_gradient(x)

    limit = MAX_ITER[method]
    if method == "gradient":
        res = minimize(
            fun_grad,
            x0,
            jac=True,
            method="L-BFGS-B",
            bounds=bounds,
            options={"maxiter": limit, "ftol": 1e-12, "gtol": 1e-9},
        )
        return np.asarray(res.x)
    if method == "slsqp":
        res = minimize(
            fun, x0, method="SLSQP", bounds=bounds, options={"maxiter": limit, "ftol": 1e-12}
        )
        return np.asarray(res.x)

    def resid(x: F64) -> F64:
        count.misfit += 1
        r, _ = model.residuals(x, jacobian=False)
        return np.where(np.isfinite(r), r, 1e3)  # least_squares needs finite residuals

    def jac(x: F64) -> F64:
        count.gradient += 1
        _, j = model.residuals(x)
        assert j is not None
        return np.nan_to_num(j)

    lo = [-np.inf if b[0] is None else b[0] for b in bounds]
    hi = [np.inf if b[1] is None else b[1] for b in bounds]
    res = least_squares(
        resid, x0, jac=jac, bounds=(lo, hi), method="trf", x_scale=1.0,
        ftol=1e-12, xtol=1e-10, gtol=1e-12, max_nfev=limit,
    )  # fmt: skip
    return np.asarray(res.x)


def _nelder_mead(
    model: SpinMisfit,
    spin_body_axis: ArrayLike | None,
    start: tuple[float, float, float],
    x0: F64,
    bounds: list,
    step: float,
    count: _Counter,
) -> Refined:
    """Nelder-Mead over (RA, Dec, phase [, f]) [deg] on :func:`.spin_axis_misfit.exact_misfit`."""
    from scipy.optimize import minimize

    from speclight.estimate.spin_axis.spin_axis_misfit import exact_misfit

    free = model.free_period
    z0 = np.array([*start, np.degrees(x0[3])] if free else list(start), dtype=float)

    def period(z: F64) -> float:
        return model.period_s(np.array([0.0, 0.0, 0.0, np.radians(z[3])])) if free else 0.0

    def fun(z: F64) -> float:
        count.misfit += 1
        geo = model.geo
        if free:
            f = np.radians(z[3])
            if not bounds[3][0] <= f <= bounds[3][1]:
                return float("inf")
            geo = dataclasses.replace(geo, period_s=period(z))
        return exact_misfit(
            model.bmap, geo, model.y, spin_body_axis, z[0], z[1], z[2], model.ranging
        )

    simplex = np.vstack([z0, z0 + np.diag(np.full(z0.size, step))])
    simplex[:, 1] = np.clip(simplex[:, 1], -90.0, 90.0)
    res = minimize(
        fun,
        z0,
        method="Nelder-Mead",
        options={
            "initial_simplex": simplex,
            "xatol": 0.05,
            "fatol": 1e-9,
            "maxiter": MAX_ITER["nelder-mead"],
        },
    )
    z = np.asarray(res.x, dtype=float)
    per = period(z) if free else model.geo.period_s
    return Refined(
        float(z[0] % 360.0), float(z[1]), float(z[2] % 360.0), float(res.fun), per, count.misfit, 0
    )
