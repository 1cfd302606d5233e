"""Roughness fit: bounded SLSQP over the roughness, the band scales in closed form.

Variable projection (Golub & Pereyra 1973, doi:10.1137/0710036): bounded SLSQP
(:func:`scipy.optimize.minimize`, Kraft 1988) minimises ``chi^2(alpha)`` over the roughness
values ``alpha`` with the band scales solved in closed form at every ``alpha``
(:func:`speclight.estimate.fitting.fit.fit_scales`). ``model(alpha)`` is called once per distinct
value (cached), which keeps the number of simulations down:

* one roughness: the start and :data:`SCAN_POINTS` log-spaced values over the bounds are
  simulated first and SLSQP starts from the best (far from the minimum chi2 is nearly flat);
  if chi2 at a neighbour of the best is within one reduced chi2, the data do not tell the
  values apart and the fit stops there (``flat``);
* SLSQP minimises log chi2 in variables scaled by its curvature at the start, so that its
  first step is a Newton step rather than a jump to a bound;
* the gradient is a central difference (a forward one shifts the minimum by half a step),
  of half-step :data:`ROUGHNESS_STEP`; when the fitted std is much smaller, SLSQP resumes
  with a step of one std.

Uncertainties are those of :mod:`speclight.estimate.fitting.fit`, from the joint Jacobian in the
scales and roughness. After the fit, chi2 is evaluated at two standard deviations on each
side of every roughness (``profile``): a true minimum rises by about 4 (reduced chi2 units) on
both sides; a side that rises by less than 1 or falls says that the linearised std does not
hold (the data bound the parameter on one side only, or the fit stopped on a slope).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize

from speclight.estimate.fitting.fit import F64, ScaleFit, fit_scales, joint_std, masked_weights

#: Half the central-difference step of the roughness gradient and Jacobian [1], at first;
#: once a pass of SLSQP has estimated the standard deviation, one std (down to FD_MIN).
ROUGHNESS_STEP = 2e-3
#: Smallest half step of the differences [1].
FD_MIN = 1e-6
#: Roughness values are rounded to this before simulating (the cache key) [1].
ROUGHNESS_RESOLUTION = 1e-8
#: SLSQP stops when an iteration lowers chi2 by less than FTOL reduced chi2 (FTOL x chi2 /
#: number of data; SLSQP minimises log chi2 with ftol = FTOL / number of data) [1].
FTOL = 1e-2
#: The check of the minimum: chi2 is evaluated at PROFILE_SIGMAS standard deviations on each
#: side of every fitted roughness, where a quadratic minimum rises by PROFILE_SIGMAS^2 (in
#: units of the reduced chi2); a side that rises by less than 1 is not constrained.
PROFILE_SIGMAS = 2.0
#: Roughness values tried before SLSQP starts, log-spaced over the bounds (one roughness).
SCAN_POINTS = 7
#: SLSQP runs at most this many times, each from where the last stopped, while it fails or
#: the difference step shrinks (see the code).
MAX_PASSES = 4


@dataclass
class RoughnessFit:
    """Result of :func:`fit_roughness`.

    Attributes
    ----------
    roughness, roughness_std
        (K,) fitted roughness values and their standard deviations [1].
    scales
        The band scales at the fitted roughness (:class:`ScaleFit`; their ``scale_std`` from
        the joint covariance, so they include the roughness's uncertainty; when ``flat``, at
        least half the spread of the scales over the scanned roughness values whose chi2 is
        within one reduced chi2 of the best).
    model
        (N, B) simulated rates at the fitted roughness (unscaled) [s-1].
    success
        SLSQP's verdict; ``message`` its message.
    n_simulations
        Distinct roughness values simulated.
    derivative
        (K,) largest |d model / d alpha| over epochs and bands, relative to the largest
        model rate (0: the data cannot see this roughness).
    profile
        (K, 2) rise of chi2 (in units of the reduced chi2) at ``-/+ PROFILE_SIGMAS`` standard
        deviations of each roughness (:data:`PROFILE_SIGMAS`); about 4 at a true minimum.
    flat
        Why the roughness was not refined after the scan (one roughness whose chi2 hardly
        changes between scan points a factor 2.2 apart), or "".
    """

    roughness: F64
    roughness_std: F64
    scales: ScaleFit
    model: F64
    success: bool
    message: str
    n_iterations: int
    n_simulations: int
    derivative: F64 = field(default_factory=lambda: np.zeros(0))
    profile: F64 = field(default_factory=lambda: np.zeros((0, 2)))
    flat: str = ""


def fit_roughness(
    model: Callable[[F64], F64],
    measured: F64,
    sigma: F64,
    start: F64,
    bounds: tuple[float, float] = (0.01, 1.0),
    *,
    fit_scale: bool = True,
    on_iteration: Callable[[int, F64, float], None] | None = None,
    max_iterations: int = 50,
    start_model: F64 | None = None,
    scan: bool = True,
) -> RoughnessFit:
    """Fit roughness values (and the band scales) by bounded SLSQP with variable projection.

    Parameters
    ----------
    model
        ``model(alpha)`` -> (N, B) simulated rates [s-1] for roughness values (K,); called
        once per distinct value (cached here).
    measured, sigma
        (N, B) measured rates and their sigmas [s-1].
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
        Simulate the :data:`SCAN_POINTS` values first and start from the best (one
        roughness); ``False`` starts SLSQP at ``start`` (to measure how far SLSQP alone
        converges from, bench/bench_fit_gradient.py).
    """
    cache: dict[tuple[float, ...], F64] = {}
    lo, hi = float(bounds[0]), float(bounds[1])
    if start_model is not None and np.all((start >= lo) & (start <= hi)):
        key = tuple(float(x) for x in np.round(np.clip(start, lo, hi) / ROUGHNESS_RESOLUTION))
        cache[key] = np.asarray(start_model, dtype=float)

    def simulate(alpha: F64) -> F64:
        key = tuple(float(x) for x in np.round(np.clip(alpha, lo, hi) / ROUGHNESS_RESOLUTION))
        if key not in cache:
            cache[key] = np.asarray(model(np.array(key) * ROUGHNESS_RESOLUTION), dtype=float)
        return cache[key]

    def chi2(alpha: F64) -> float:
        c = simulate(alpha)
        if fit_scale:
            return float(np.sum(fit_scales(c, measured, sigma).chi2))
        w, cc, m = masked_weights(c, measured, sigma)
        return float(np.sum(w * (m - cc) ** 2))

    x0 = np.clip(np.asarray(start, dtype=float), lo, hi)
    n_data = int(np.count_nonzero(masked_weights(simulate(x0), measured, sigma)[0]))

    def objective(alpha: F64) -> float:
        # log chi2: its changes are relative ones, so one ftol serves a start far from the
        # minimum (chi2 huge) and the end (chi2 near the number of data) alike
        return float(np.log(max(chi2(alpha), 1e-300)))

    fd = np.full(x0.size, ROUGHNESS_STEP)  # half the difference step, per roughness

    def gradient(alpha: F64) -> F64:
        g = np.zeros(alpha.size)
        for k in range(alpha.size):  # central: a forward difference would shift the minimum
            a, b = _steps(alpha, k, lo, hi, fd[k])
            g[k] = (objective(b) - objective(a)) / (b[k] - a[k])
        return g

    iteration = [0]

    def callback(alpha: F64) -> None:
        iteration[0] += 1
        if on_iteration is not None:
            on_iteration(iteration[0], alpha, chi2(alpha))

    n_par = x0.size + (measured.shape[1] if fit_scale else 0)

    def unit(value: float) -> float:  # the reduced chi2 (at least 1)
        return max(1.0, value / max(n_data - n_par, 1))

    x, flat = _scan_start(x0, chi2, lo, hi, unit) if scan else (x0, "")
    success, message = not flat, "not refined: the scan found chi2 flat" if flat else ""
    if flat:  # the local std of a flat chi2 is noise: none is given (nor simulated)
        lin = _linearise(simulate, x, measured, sigma, fit_scale, (lo, hi), None)
        if fit_scale:  # the scales' std covers the roughness values the data cannot tell apart
            tried = [x0, *[np.array([g]) for g in np.geomspace(lo, hi, SCAN_POINTS)]]
            least = min(chi2(g) for g in tried)
            alike = [g for g in tried if chi2(g) - least < unit(least)]
            found = np.array([fit_scales(simulate(g), measured, sigma).scale for g in alike])
            spread = (found.max(axis=0) - found.min(axis=0)) / 2
            lin.scales.scale_std = np.maximum(lin.scales.scale_std, spread)
    for _ in range(0 if flat else MAX_PASSES):
        # SLSQP's first step is a steepest-descent step of unit length in its variables; in
        # u = (alpha - x) / h with h = 1 / sqrt(curvature of the objective at x) it is a
        # Newton step instead of a jump to a bound (the curvature comes from the gradient's
        # cached points)
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
        lin = _linearise(simulate, x, measured, sigma, fit_scale, (lo, hi), fd)
        # a difference step much wider than the std misjudges the gradient near the
        # minimum: resume with a step of one std (down to FD_MIN)
        finite = np.where(np.isfinite(lin.std_alpha), lin.std_alpha, ROUGHNESS_STEP)
        step = np.clip(finite, FD_MIN, ROUGHNESS_STEP)
        if success and np.all(step >= fd / 3):
            break
        fd = np.minimum(fd, step)
    alpha, c, scales = x, lin.model, lin.scales
    std_alpha, derivative = lin.std_alpha, lin.derivative
    profile = chi2_profile(chi2, alpha, std_alpha, (lo, hi), n_data, fit_scale, scales.chi2)
    return RoughnessFit(
        roughness=alpha,
        roughness_std=std_alpha,
        scales=scales,
        model=c,
        success=bool(success),
        message=str(message),
        n_iterations=iteration[0],
        n_simulations=len(cache),
        derivative=derivative,
        profile=profile,
        flat=flat,
    )


@dataclass
class _Linearised:
    model: F64
    scales: ScaleFit
    std_alpha: F64
    derivative: F64


def _linearise(
    simulate: Callable[[F64], F64],
    alpha: F64,
    measured: F64,
    sigma: F64,
    fit_scale: bool,
    bounds: tuple[float, float],
    fd: F64 | None,
) -> _Linearised:
    """Scales, Jacobian and standard deviations at ``alpha`` (module doc: uncertainties)."""
    c = simulate(alpha)
    scales = fit_scales(c, measured, sigma)
    if not fit_scale:  # the scales stay 1: their chi2, no spread
        w, cc, m = masked_weights(c, measured, sigma)
        n_b = c.shape[1]
        chi2_fixed = np.sum(w * (m - cc) ** 2, axis=0)
        scales = ScaleFit(np.ones(n_b), np.zeros(n_b), chi2_fixed, scales.n_used)
    if fd is None:  # no roughness derivative: the scales' std at this roughness
        return _Linearised(c, scales, np.full(alpha.size, np.nan), np.full(alpha.size, np.nan))
    jac_cols, derivative = _jacobian(simulate, alpha, c, scales.scale, bounds, fit_scale, fd)
    std_alpha, std_scale = joint_std(jac_cols, c, measured, sigma, scales.scale, fit_scale)
    if fit_scale:
        scales.scale_std = std_scale
    return _Linearised(c, scales, std_alpha, derivative)


def chi2_profile(
    chi2: Callable[[F64], float],
    alpha: F64,
    std: F64,
    bounds: tuple[float, float],
    n_data: int,
    fit_scale: bool,
    chi2_bands: F64,
) -> F64:
    """Rise of chi2 at -/+ PROFILE_SIGMAS std of each roughness, in units of the reduced
    chi2 (K, 2); NaN for a side beyond a bound or an unconstrained (infinite std) value.

    A quadratic minimum rises by PROFILE_SIGMAS^2 = 4 on both sides. Much less means that the
    linearised std is wrong: chi2 is flat on that side (the data give only a bound), or the
    fit stopped on a slope (negative: chi2 is lower there).

    Parameters
    ----------
    chi2
        Chi-square as a function of the roughness values (K,).
    alpha, std
        The fitted roughness values and their standard deviations (K,).
    bounds
        The roughness bounds (low, high).
    n_data
        Measurements fitted (finite entries).
    fit_scale
        Whether a scale per band was fitted (its parameters count in the dof).
    chi2_bands
        The chi-square per band (B,): its size is the number of scales fitted.
    """
    lo, hi = bounds
    best = chi2(alpha)
    n_par = alpha.size + (chi2_bands.size if fit_scale else 0)
    reduced = max(1.0, best / max(n_data - n_par, 1))
    out = np.full((alpha.size, 2), np.nan)
    for k in range(alpha.size):
        if not np.isfinite(std[k]) or std[k] > hi - lo:
            continue
        step = max(PROFILE_SIGMAS * std[k], 10 * ROUGHNESS_RESOLUTION)
        for side, sign in enumerate((-1.0, 1.0)):
            a = alpha.copy()
            a[k] += sign * step
            if lo <= a[k] <= hi:
                out[k, side] = (chi2(a) - best) / reduced
    return out


def _jacobian(
    simulate: Callable[[F64], F64],
    alpha: F64,
    c: F64,
    scale: F64,
    bounds: tuple[float, float],
    fit_scale: bool,
    fd: F64,
) -> tuple[list[F64], F64]:
    """d(s_j c_tj)/d alpha_k as (N, B) arrays (central differences, the points of the last
    gradient), and their size relative to the model."""
    lo, hi = bounds
    s = np.where(np.isfinite(scale), scale, 0.0) if fit_scale else np.ones(c.shape[1])
    cols, size = [], np.zeros(alpha.size)
    top = np.nanmax(np.abs(c)) if np.any(np.isfinite(c)) else 0.0
    for k in range(alpha.size):
        a, b = _steps(alpha, k, lo, hi, fd[k])
        d = (simulate(b) - simulate(a)) / (b[k] - a[k])
        cols.append(d * s[None, :])
        size[k] = float(np.nanmax(np.abs(d)) / top) if top > 0 and np.any(np.isfinite(d)) else 0.0
    return cols, size


def _scan_start(
    x0: F64, chi2: Callable[[F64], float], lo: float, hi: float, unit: Callable[[float], float]
) -> tuple[F64, str]:
    """For one roughness: where to start SLSQP, and why not to ("" to go on).

    chi2 is nearly flat far from the minimum (a glint that does not overlap the measured one
    misfits by about as much whatever its width), where SLSQP's first steps wander; so the
    start and SCAN_POINTS log-spaced values over the bounds are simulated first and SLSQP
    starts from the best. When chi2 at a scan neighbour of the best (the next value below or
    above, a factor of about 2.2 away) is within one reduced chi2 (``unit(chi2)``) of the
    best, the data do not tell these values apart and SLSQP would only chase noise: the
    reason is returned, with the start kept if it is as good as the best to within that
    unit. Several roughness values start as given.
    """
    if x0.size != 1:
        return x0, ""
    grid = np.geomspace(lo, hi, SCAN_POINTS)
    values = np.array([chi2(np.array([g])) for g in grid])
    start_chi2 = chi2(x0)
    k = int(np.argmin(values))
    if start_chi2 < values[k]:
        best, best_chi2 = float(x0[0]), start_chi2
    else:
        best, best_chi2 = float(grid[k]), float(values[k])
    below, above = grid[grid < best], grid[grid > best]
    rise = {}
    if below.size:
        rise["below"] = (float(values[grid < best][-1]) - best_chi2, float(below[-1]))
    if above.size:
        rise["above"] = (float(values[grid > best][0]) - best_chi2, float(above[0]))
    flat = {side: r for side, r in rise.items() if r[0] < unit(best_chi2)}
    if not flat:
        return np.array([best]), ""
    keep = x0 if start_chi2 - best_chi2 < unit(best_chi2) else np.array([best])
    parts = [
        f"chi2 changes by less than one reduced chi2 from {best:.3g} to {at:.3g}"
        for _, at in flat.values()
    ]
    bounded = [f"{side} {at:.3g} (chi2 +{r / unit(best_chi2):.3g})"
               for side, (r, at) in rise.items() if side not in flat]  # fmt: skip
    text = " and ".join(parts)
    if bounded:
        text += f"; it is bounded only on one side: {bounded[0]}"
    if keep is x0 and float(x0[0]) != best:
        text += f"; the start {float(x0[0]):.3g} is as good and is kept"
    return keep, text


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
    "RoughnessFit",
    "chi2_profile",
    "fit_roughness",
]
