"""Fit of simulated to measured count rates: per-band scales and roughness (plain arrays).

The model of the measured rate ``m[t, j]`` (epoch t, band j) is ``s_j * c[t, j](alpha)``: the
simulated count rate ``c`` of the scenario, for the roughness values ``alpha`` of its rough
materials, times a scale ``s_j`` on the target's reflectance in band j. Intensity is linear
in the reflectance of a Lambertian or microfacet surface (see
:func:`speclight.render.material_contributions`), so for fixed ``alpha`` the scales minimise

.. math::

    \\chi^2 = \\sum_{t, j} w_{tj} (m_{tj} - s_j c_{tj})^2, \\qquad w_{tj} = 1 / \\sigma_{tj}^2,

in closed form (one weighted linear least-squares problem per band):
``s_j = sum_t w m c / sum_t w c^2``. Only the roughness needs new simulations. It is fitted by
variable projection (Golub & Pereyra 1973, doi:10.1137/0710036): bounded SLSQP
(:func:`scipy.optimize.minimize`, Kraft 1988) minimises ``chi^2(alpha)`` with the scales
solved in closed form at every ``alpha``; the gradient is a central difference whose
simulations are cached with the others (``model(alpha)`` is called once per distinct value).
After the fit, chi2 is evaluated at two standard deviations on each side of every roughness
(``profile``): a true minimum rises by about 4 (reduced chi2 units) on both sides; a side that
rises by less than 1 or falls says that the linearised std does not hold (the data bound the
parameter on one side only, or the fit stopped on a slope).

Uncertainties: the covariance of all fitted parameters is ``(J^T W J)^-1`` at the optimum (J
the Jacobian of the model in the scales and roughness), multiplied by ``max(1, chi^2 / dof)``:
when the residuals exceed the measurement sigmas (sigmas that leave out sky and read noise,
or a model that is not exact, e.g. a rendered target), the spread of the residuals, not the
sigmas, measures how well the data pin the parameters (as ``scipy.optimize.curve_fit`` does
with ``absolute_sigma=False``); it is never scaled down.

Missing sigmas: the shot noise of the measured rate,
``sigma = sqrt(max(m, floor) / (t_exp n))`` for ``n`` exposures of ``t_exp`` seconds averaged,
with ``floor`` one detected electron per averaged exposure time (``1 / (t_exp n)``) so that
faint or negative (background-subtracted) rates do not get near-infinite weights.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import minimize

F64 = NDArray[np.float64]

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


def shot_noise_sigma(rate_per_s: F64, exposure_s: float, n_samples: NDArray | int = 1) -> F64:
    """Shot-noise standard deviation of measured rates [s-1] (module doc: the floor).

    Parameters
    ----------
    rate_per_s
        (N, B) measured rates [s-1].
    exposure_s
        Exposure time of one measurement [s].
    n_samples
        (N,) number of measurements averaged into each rate (1 unless binned).
    """
    r = np.asarray(rate_per_s, dtype=float)
    t = float(exposure_s) * np.asarray(n_samples, dtype=float)
    if r.ndim == 2 and t.ndim == 1:
        t = t[:, None]
    t = np.broadcast_to(t, r.shape)
    electrons = np.maximum(np.where(np.isfinite(r), r, np.nan) * t, 1.0)
    return np.asarray(np.sqrt(electrons) / t, dtype=np.float64)


@dataclass
class ScaleFit:
    """Closed-form weighted least-squares scales, one per band.

    Attributes
    ----------
    scale, scale_std
        (B,) the scales and their standard deviations (NaN where a band is unconstrained).
    chi2
        (B,) weighted sum of squared residuals per band.
    n_used
        (B,) epochs used per band.
    """

    scale: F64
    scale_std: F64
    chi2: F64
    n_used: NDArray[np.int64]


def fit_scales(model: F64, measured: F64, sigma: F64) -> ScaleFit:
    """Per-band scales ``s_j`` minimising ``sum_t (m - s_j c)^2 / sigma^2`` (module doc).

    Entries where any of the three is not finite, or sigma <= 0, are skipped. The standard
    deviation is ``sqrt(1 / sum_t w c^2)`` times ``sqrt(max(1, chi2_j / (n_j - 1)))``.

    Parameters
    ----------
    model, measured, sigma
        (N, B) simulated rates ``c``, measured rates ``m`` and their sigmas [s-1].
    """
    w, c, m = _weights(model, measured, sigma)
    wcc = np.sum(w * c * c, axis=0)
    wmc = np.sum(w * m * c, axis=0)
    n_used = np.sum(w > 0, axis=0).astype(np.int64)
    ok = (wcc > 0) & (n_used > 0)
    scale = np.where(ok, wmc / np.where(ok, wcc, 1.0), np.nan)
    chi2 = np.sum(w * (m - np.where(ok, scale, 0.0) * c) ** 2, axis=0)
    dof = np.maximum(n_used - 1, 1)
    inflate = np.maximum(1.0, chi2 / dof)
    std = np.where(ok, np.sqrt(inflate / np.where(ok, wcc, 1.0)), np.nan)
    return ScaleFit(scale, std, chi2, n_used)


def _weights(model: F64, measured: F64, sigma: F64) -> tuple[F64, F64, F64]:
    c = np.asarray(model, dtype=float)
    m = np.asarray(measured, dtype=float)
    s = np.asarray(sigma, dtype=float)
    good = np.isfinite(c) & np.isfinite(m) & np.isfinite(s) & (s > 0)
    w = np.where(good, 1.0 / np.where(good, s, 1.0) ** 2, 0.0)
    return w, np.where(good, c, 0.0), np.where(good, m, 0.0)


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
        w, cc, m = _weights(c, measured, sigma)
        return float(np.sum(w * (m - cc) ** 2))

    x0 = np.clip(np.asarray(start, dtype=float), lo, hi)
    n_data = int(np.count_nonzero(_weights(simulate(x0), measured, sigma)[0]))

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

    x, flat = _scan_start(x0, chi2, lo, hi, unit)
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
    profile = _profile(chi2, alpha, std_alpha, (lo, hi), n_data, fit_scale, scales.chi2)
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
        w, cc, m = _weights(c, measured, sigma)
        n_b = c.shape[1]
        chi2_fixed = np.sum(w * (m - cc) ** 2, axis=0)
        scales = ScaleFit(np.ones(n_b), np.zeros(n_b), chi2_fixed, scales.n_used)
    if fd is None:  # no roughness derivative: the scales' std at this roughness
        return _Linearised(c, scales, np.full(alpha.size, np.nan), np.full(alpha.size, np.nan))
    jac_cols, derivative = _jacobian(simulate, alpha, c, scales.scale, bounds, fit_scale, fd)
    std_alpha, std_scale = _covariance(jac_cols, c, measured, sigma, scales.scale, fit_scale)
    if fit_scale:
        scales.scale_std = std_scale
    return _Linearised(c, scales, std_alpha, derivative)


def _profile(
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


def _covariance(
    cols: list[F64], c: F64, measured: F64, sigma: F64, scale: F64, fit_scale: bool
) -> tuple[F64, F64]:
    """Standard deviations of roughness and scales from ``(J^T W J)^-1`` (module doc)."""
    n_b = c.shape[1]
    s = np.where(np.isfinite(scale), scale, 0.0) if fit_scale else np.ones(n_b)
    w, cc, m = _weights(c, measured, sigma)
    sqrt_w = np.sqrt(w).ravel()
    blocks = []
    if fit_scale:
        for j in range(n_b):
            col = np.zeros_like(cc)
            col[:, j] = cc[:, j]
            blocks.append(col.ravel())
    blocks += [np.where(w > 0, np.nan_to_num(d), 0.0).ravel() for d in cols]
    jac = np.stack(blocks, axis=1) * sqrt_w[:, None]
    resid = (m - s[None, :] * cc).ravel() * sqrt_w
    n_used = int(np.count_nonzero(w))
    dof = max(n_used - jac.shape[1], 1)
    inflate = max(1.0, float(resid @ resid) / dof)
    info = jac.T @ jac
    try:
        cov = np.linalg.inv(info) * inflate
        std = np.sqrt(np.where(np.diag(cov) >= 0, np.diag(cov), np.nan))
        if np.linalg.cond(info) > 1e14:
            std = np.full(jac.shape[1], np.inf)
    except np.linalg.LinAlgError:
        std = np.full(jac.shape[1], np.inf)
    k0 = n_b if fit_scale else 0
    std_scale = std[:n_b] if fit_scale else np.zeros(n_b)
    return std[k0:], std_scale


__all__ = [
    "ROUGHNESS_STEP",
    "RoughnessFit",
    "ScaleFit",
    "fit_roughness",
    "fit_scales",
    "shot_noise_sigma",
]
