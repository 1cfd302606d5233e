"""Roughness fit by bounded SLSQP over the roughness, the band scales in closed form.

The objective is chi2 over the roughness with the scales projected out
(:class:`~speclight.estimate.fitting.roughness_problem.RoughnessProblem`); every distinct
roughness value is simulated once (cached). The fit runs in three stages, shared with the
gradient method (:mod:`.gradient_fit`), which differs in the local stage only:

1. the **scan** (:mod:`.roughness_scan`): a coordinate search over a log grid of every
   roughness, which finds the basin of the minimum from any start in the bounds;
2. the **local method** on all of them (also those the scan found flat: its verdict is
   taken far from the minimum, with a reduced chi2 that a misfit of another material
   inflates; a box-wing's wings, which glint together, were left at a bound so): bounded
   SLSQP (:func:`scipy.optimize.minimize`, Kraft 1988) on log chi2, in variables scaled by
   its curvature at the start (so that its first step is a Newton step rather than a jump
   to a bound); the gradient is a central difference (a forward one shifts the minimum by
   half a step) of half-step :data:`ROUGHNESS_STEP`, and when the fitted std is much
   smaller, SLSQP resumes with a step of one std. It is repeated without the measurements
   that lie more than ``clip_sigma`` robust sigmas from the fit (outliers,
   :mod:`.fit_quality`) while it finds new ones;
3. the **uncertainties** and what cannot be claimed (:mod:`.roughness_uncertainty`);
4. with several materials, where the fit misfits the data, stages 1-3 once more from the
   best point of the scan's common line, the fit of lower chi2 kept (:func:`solve`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import minimize

from speclight.estimate.fitting.fit import F64, joint_std
from speclight.estimate.fitting.fit_quality import (
    CLIP_SIGMA,
    MAX_ROUNDS,
    misfit_text,
    outlier_mask,
)
from speclight.estimate.fitting.noise_model import PoissonNoise
from speclight.estimate.fitting.roughness_problem import ROUGHNESS_RESOLUTION, RoughnessProblem
from speclight.estimate.fitting.roughness_scan import SCAN_POINTS, common_start, coordinate_scan
from speclight.estimate.fitting.roughness_uncertainty import (
    PROFILE_SIGMAS,
    RoughnessFit,
    chi2_profile,
    finish,
)

#: Half the central-difference step of the roughness gradient and Jacobian [1], at first;
#: once a pass of SLSQP has estimated the standard deviation, one std (down to FD_MIN).
ROUGHNESS_STEP = 2e-3
#: Smallest half step of the differences [1].
FD_MIN = 1e-6
#: SLSQP stops when an iteration lowers chi2 by less than FTOL reduced chi2 (FTOL x chi2 /
#: number of data; SLSQP minimises log chi2 with ftol = FTOL / number of data) [1].
FTOL = 1e-2
#: SLSQP runs at most this many times, each from where the last stopped, while it fails or
#: the difference step shrinks (see the code).
MAX_PASSES = 4


def fit_roughness(
    model: Callable[[F64], F64],
    measured: F64,
    sigma: F64 | PoissonNoise,
    start: F64,
    bounds: tuple[float, float] = (0.01, 1.0),
    *,
    fit_scale: bool = True,
    on_iteration: Callable[[int, F64, float], None] | None = None,
    max_iterations: int = 50,
    start_model: F64 | None = None,
    scan: bool = True,
    clip_sigma: float | None = CLIP_SIGMA,
) -> RoughnessFit:
    """Fit roughness values (and the band scales): scan, SLSQP, uncertainties (module doc).

    Parameters
    ----------
    model
        ``model(alpha)`` -> (N, B) simulated rates [s-1] for roughness values (K,); called
        once per distinct value (cached here).
    measured
        (N, B) measured rates [s-1].
    sigma
        (N, B) their standard deviations [s-1], or a :class:`.noise_model.PoissonNoise`
        (the model's own shot noise).
    start
        (K,) initial roughness values.
    bounds
        Lower and upper bound of every roughness.
    fit_scale
        Fit the band scales (else they stay 1).
    on_iteration
        Called with (iteration, alpha, chi2) after each SLSQP iteration.
    max_iterations
        SLSQP's iteration limit.
    start_model
        ``model(start)`` when already simulated (it is not simulated again).
    scan
        Scan the bounds first (:mod:`.roughness_scan`); ``False`` starts SLSQP at ``start``
        (to measure how far SLSQP alone converges from, bench/bench_fit_gradient.py).
    clip_sigma
        Leave out measurements this many robust sigmas from the fit (:mod:`.fit_quality`);
        None keeps every one.
    """
    problem = RoughnessProblem(model, measured, sigma, bounds, fit_scale=fit_scale)
    x0 = np.clip(np.asarray(start, dtype=float), problem.lo, problem.hi)
    if start_model is not None:
        problem.seed(x0, start_model)
    return solve(problem, x0, slsqp_refine, scan=scan, on_iteration=on_iteration,
                 max_iterations=max_iterations, clip_sigma=clip_sigma)  # fmt: skip


#: A local method: (problem, start (K,), which to fit (K,), on_iteration, max_iterations) ->
#: (roughness (K,), success, message, iterations, central-difference half steps or None).
Refine = Callable[
    [RoughnessProblem, F64, NDArray[np.bool_], Callable[[int, F64, float], None] | None, int],
    tuple[F64, bool, str, int, F64 | None],
]


def solve(
    problem: RoughnessProblem,
    start: F64,
    refine: Refine,
    *,
    scan: bool = True,
    on_iteration: Callable[[int, F64, float], None] | None = None,
    max_iterations: int = 50,
    clip_sigma: float | None = CLIP_SIGMA,
) -> RoughnessFit:
    """The stages of a roughness fit (module doc) with the local method ``refine``; the local
    method is repeated without the outliers (:mod:`.fit_quality`) while it finds new ones.

    With several materials, a fit that misfits the data (:func:`.fit_quality.misfit_text`)
    is run once more from the best point of the scan's common line
    (:func:`.roughness_scan.common_start`: every roughness at one grid value), and the fit
    of lower chi2 is kept: a coordinate scan moves one material at a time and stays in a
    basin that only a joint move leaves (a box-wing's two wings, whose light adds: from
    0.5 and 0.8 it kept them at 0.54 and 0.99 for a truth of 0.05 and 0.08, chi2 per
    degree of freedom 42).
    """

    def from_(x0: F64) -> RoughnessFit:
        return _solve_from(problem, x0, refine, scan=scan, on_iteration=on_iteration,
                           max_iterations=max_iterations, clip_sigma=clip_sigma)  # fmt: skip

    fit = from_(start)
    if not scan or fit.roughness.size < 2 or not _misfits(problem, fit.roughness):
        return fit
    other = common_start(problem, fit.roughness.size)
    if np.allclose(other, fit.roughness):
        return fit
    again = from_(other)
    better = problem.chi2(again.roughness) < problem.chi2(fit.roughness)
    return again if better else fit


def _misfits(problem: RoughnessProblem, x: F64) -> bool:
    """The chi2 at ``x`` is far above its degrees of freedom (:mod:`.fit_quality`)."""
    return bool(misfit_text(problem.chi2(x), problem.n_data, problem.n_par(x.size)))


def _solve_from(
    problem: RoughnessProblem,
    start: F64,
    refine: Refine,
    *,
    scan: bool,
    on_iteration: Callable[[int, F64, float], None] | None,
    max_iterations: int,
    clip_sigma: float | None,
) -> RoughnessFit:
    """Scan, local method and outlier rounds, uncertainties: one start (:func:`solve`)."""
    x = np.clip(np.asarray(start, dtype=float), problem.lo, problem.hi)
    flat = np.zeros(x.size, dtype=bool)
    if scan:
        found = coordinate_scan(problem, x)
        x, flat = found.best, found.flat
    # every value is refined, the flat ones too: a misfit elsewhere can hide a slope
    free = np.ones(x.size, dtype=bool)
    success, message, iterations, fd = True, "", 0, None
    drop = np.zeros(problem.likelihood.m.shape, dtype=bool)
    for round_ in range(MAX_ROUNDS + 1):
        if np.any(free):
            x, success, message, n, fd = refine(problem, x, free, on_iteration, max_iterations)
            iterations += n
        new = outlier_mask(problem.likelihood, problem.fitted(x), clip_sigma)
        if round_ == MAX_ROUNDS or not np.any(new):
            break
        drop |= new
        problem = problem.without(drop)
    # the scan's flat verdict was taken far from the minimum, with a reduced chi2 that a
    # misfit elsewhere inflates: what is constrained is judged at the fit (its std, profile)
    flat = np.zeros(x.size, dtype=bool)
    fit = finish(problem, x, free=free, flat=flat, fd=fd, success=success, message=message,
                 n_iterations=iterations)  # fmt: skip
    fit.outliers = drop
    return fit


def slsqp_refine(
    problem: RoughnessProblem,
    start: F64,
    free: NDArray[np.bool_],
    on_iteration: Callable[[int, F64, float], None] | None,
    max_iterations: int,
) -> tuple[F64, bool, str, int, F64]:
    """Bounded SLSQP over the roughness values ``free`` (module doc, stage 2)."""
    lo, hi = problem.lo, problem.hi
    idx = np.flatnonzero(free)
    full = np.asarray(start, dtype=float).copy()

    def point(sub: F64) -> F64:
        a = full.copy()
        a[idx] = np.clip(sub, lo, hi)
        return a

    def objective(sub: F64) -> float:
        # log chi2: its changes are relative ones, so one ftol serves a start far from the
        # minimum (chi2 huge) and the end (chi2 near the number of data) alike
        return float(np.log(max(problem.chi2(point(sub)), 1e-300)))

    fd = np.full(idx.size, ROUGHNESS_STEP)  # half the difference step, per roughness

    def gradient(sub: F64) -> F64:
        g = np.zeros(sub.size)
        for k in range(sub.size):  # central: a forward difference would shift the minimum
            a, b = _steps(sub, k, lo, hi, fd[k])
            g[k] = (objective(b) - objective(a)) / (b[k] - a[k])
        return g

    iteration = [0]

    def callback(sub: F64) -> None:
        iteration[0] += 1
        if on_iteration is not None:
            on_iteration(iteration[0], point(sub), problem.chi2(point(sub)))

    n_data = problem.n_data
    x = full[idx]
    success, message = False, ""
    for _ in range(MAX_PASSES):
        # SLSQP's first step is a steepest-descent step of unit length in its variables; in
        # u = (alpha - x) / h with h = 1 / sqrt(curvature of the objective at x) it is a
        # Newton step instead of a jump to a bound
        h = _step_scale(objective, x, lo, hi, fd)
        res = minimize(
            lambda u, x=x, h=h: objective(x + h * u),
            np.zeros(x.size),
            jac=lambda u, x=x, h=h: gradient(x + h * u) * h,
            method="SLSQP",
            bounds=list(zip((lo - x) / h, (hi - x) / h, strict=True)),
            callback=lambda u, x=x, h=h: callback(x + h * u),
            # stop when an iteration lowers chi2 by less than FTOL x chi2 / n_data, i.e. FTOL
            # in units of the reduced chi2
            options={"maxiter": max_iterations, "ftol": FTOL / max(n_data, 1)},
        )
        x = np.clip(x + h * np.asarray(res.x, dtype=float), lo, hi)
        success, message = bool(res.success), str(res.message)
        # a difference step much wider than the std misjudges the gradient near the
        # minimum: resume with a step of one std (down to FD_MIN)
        std = _local_std(problem, point(x), idx, fd)
        step = np.clip(np.where(np.isfinite(std), std, ROUGHNESS_STEP), FD_MIN, ROUGHNESS_STEP)
        if success and np.all(step >= fd / 3):
            break
        fd = np.minimum(fd, step)
    steps = np.full(full.size, ROUGHNESS_STEP)
    steps[idx] = fd
    return point(x), success, message, iteration[0], steps


def _local_std(problem: RoughnessProblem, alpha: F64, idx: NDArray, fd: F64) -> F64:
    """The std of the roughness values ``idx`` at ``alpha`` (central differences)."""
    c = problem.rates(alpha)
    scales = problem.scales(alpha)
    s = np.where(np.isfinite(scales.scale), scales.scale, 0.0)
    cols = []
    for j, k in enumerate(idx):
        a, b = _steps(alpha, int(k), problem.lo, problem.hi, fd[j])
        cols.append((problem.rates(b) - problem.rates(a)) / (b[k] - a[k]) * s[None, :])
    std, _ = joint_std(cols, c, problem.likelihood, scales.scale, problem.fit_scale)
    return std


def _step_scale(objective: Callable[[F64], float], x: F64, lo: float, hi: float, fd: F64) -> F64:
    """1 / sqrt(second difference of the objective) per roughness (where it is convex)."""
    h = np.empty(x.size)
    f0 = objective(x)
    for k in range(x.size):
        a, b = _steps(x, k, lo, hi, fd[k])
        da, db = x[k] - a[k], b[k] - x[k]
        fa, fb = objective(a), objective(b)
        curv = 2 * ((fb - f0) / db - (f0 - fa) / da) / (da + db) if da > 0 and db > 0 else 0.0
        if curv > 0:
            h[k] = 1 / np.sqrt(curv)
        else:  # not convex here: a first step of a quarter of the value, downhill
            slope = abs(fb - fa) / max(da + db, 1e-300)
            h[k] = np.sqrt(max(0.25 * x[k], fd[k]) / max(slope, 1e-300))
    return np.clip(h, FD_MIN, 0.1 * (hi - lo))


def _steps(alpha: F64, k: int, lo: float, hi: float, step: float) -> tuple[F64, F64]:
    """The two points of a central difference in alpha_k (one-sided at a bound)."""
    a, b = alpha.copy(), alpha.copy()
    a[k] = max(alpha[k] - step, lo)
    b[k] = min(alpha[k] + step, hi)
    return a, b


__all__ = [
    "FD_MIN",
    "FTOL",
    "MAX_PASSES",
    "PROFILE_SIGMAS",
    "ROUGHNESS_RESOLUTION",
    "ROUGHNESS_STEP",
    "SCAN_POINTS",
    "Refine",
    "RoughnessFit",
    "chi2_profile",
    "fit_roughness",
    "slsqp_refine",
    "solve",
]
