"""What a roughness fit can claim: standard deviations, their check, and the profile ranges.

* **Standard deviations** from the joint ``(J^T W J)^-1`` in the scales and the roughness
  values (:func:`speclight.estimate.fitting.fit.joint_std`), J analytic (``--method
  gradient``) or by central differences (SLSQP).
* **Their check**: chi2 is evaluated :data:`PROFILE_SIGMAS` standard deviations on each side
  of every roughness (the scales re-fitted), where a quadratic minimum rises by
  ``PROFILE_SIGMAS^2 = 4`` in units of the reduced chi2; a side that rises by less than 1,
  or falls, says that the linearised std does not hold (the data bound the roughness on one
  side only, or the fit stopped on a slope).
* **Not constrained** is said of a roughness marked ``flat`` by the caller, whose std
  exceeds the bounds' range or whose derivative is zero,
  that stopped at a bound, or that fails the check. Its std is then not given (NaN);
  instead its **profile ranges**: the values whose chi2 (scales re-fitted, the other
  roughness values held at the fit) is within 1 and within 9 reduced chi2 of the minimum
  (:data:`PROFILE_LEVELS`: one and three standard deviations of one parameter, Wilks'
  theorem), each edge located by :data:`BISECTIONS` bisections in log roughness between the
  scan's grid values and a linear interpolation of chi2 in log roughness after them. So the
  message reads "0.05-0.2 fit within one standard deviation; outside 0.03-0.3 excluded at
  three" rather than a bound from a single grid step. The scales' std is then widened to
  the root sum of squares of their std with the unconstrained values held and half the spread
  of the scales fitted over the values within one standard deviation.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.fitting.fit import F64, ScaleFit, joint_std
from speclight.estimate.fitting.roughness_problem import ROUGHNESS_RESOLUTION, RoughnessProblem

#: The check of the minimum: chi2 is evaluated at PROFILE_SIGMAS standard deviations on each
#: side of every fitted roughness (module doc).
PROFILE_SIGMAS = 2.0
#: Rises of chi2 (in units of the reduced chi2) that bound the profile ranges: one and three
#: standard deviations of one parameter.
PROFILE_LEVELS = (1.0, 9.0)
#: Bisections in log roughness that locate each edge of a profile range.
BISECTIONS = 3


@dataclass
class RoughnessFit:
    """Result of a roughness fit (:func:`.roughness_fit.fit_roughness`,
    :func:`.gradient_fit.fit_roughness_gradient`).

    Attributes
    ----------
    roughness, roughness_std
        (K,) fitted roughness values and their standard deviations [1] (NaN where not
        constrained).
    scales
        The band scales at the fitted roughness (:class:`ScaleFit`; their ``scale_std`` from
        the joint covariance, so they include the roughness's uncertainty, widened where a
        roughness is not constrained: module doc).
    model
        (N, B) simulated rates at the fitted roughness (unscaled) [s-1].
    success, message
        The local method's verdict and message.
    n_iterations
        The local method's iterations (SLSQP) or evaluations (trust region).
    n_simulations
        Distinct roughness values simulated (render passes with ``gradient``).
    derivative
        (K,) largest |d model / d alpha| over epochs and bands, relative to the largest
        model rate (0: the data cannot see this roughness).
    profile
        (K, 2) rise of chi2 (in units of the reduced chi2) at ``-/+ PROFILE_SIGMAS`` standard
        deviations of each roughness; about 4 at a true minimum.
    unconstrained
        (K,) why each roughness is not constrained ("" where it is).
    ranges
        (K, 2, 2) the profile ranges (module doc) at the levels of :data:`PROFILE_LEVELS`,
        ``[k, level, low/high]`` [1]; NaN where the roughness is constrained.
    outliers
        (N, B) measurements left out as outliers (:mod:`.fit_quality`).
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
    unconstrained: list[str] = field(default_factory=list)
    ranges: F64 = field(default_factory=lambda: np.zeros((0, 2, 2)))
    outliers: NDArray[np.bool_] = field(default_factory=lambda: np.zeros((0, 0), dtype=bool))


def finish(
    problem: RoughnessProblem,
    x: F64,
    *,
    free: np.ndarray,
    flat: np.ndarray,
    fd: F64 | None,
    success: bool,
    message: str,
    n_iterations: int,
) -> RoughnessFit:
    """The fit's numbers at ``x`` (module doc).

    Parameters
    ----------
    problem
        The objective.
    x
        (K,) the fitted roughness values.
    free
        (K,) the values the local method fitted (the others were held where the scan put
        them).
    flat
        (K,) the scan found chi2 flat about these values.
    fd
        (K,) half steps of the central differences of the Jacobian (``None``: the model's
        analytic derivatives).
    success, message, n_iterations
        The local method's.
    """
    lo, hi = problem.lo, problem.hi
    c = problem.rates(x)
    scales = problem.scales(x)
    cols, derivative = _jacobian(problem, x, scales.scale, fd, free)
    std = np.full(x.size, np.nan)
    if np.any(free):
        std_free, std_scale = joint_std(
            [cols[k] for k in np.flatnonzero(free)], c, problem.likelihood, scales.scale,
            problem.fit_scale,
        )  # fmt: skip
        std[free] = std_free
        if problem.fit_scale:
            scales.scale_std = std_scale
    profile = chi2_profile(problem, x, std)
    reasons = [
        _reason(x[k], std[k], derivative[k], profile[k], bool(flat[k]), lo, hi)
        for k in range(x.size)
    ]
    ranges = np.full((x.size, len(PROFILE_LEVELS), 2), np.nan)
    alike_scales = [scales.scale]
    best = problem.chi2(x)
    unit = problem.unit(best, x.size)
    for k in np.flatnonzero([bool(r) for r in reasons]):
        std[k] = np.nan
        for i, level in enumerate(PROFILE_LEVELS):
            ranges[k, i] = profile_range(problem, x, int(k), level * unit, best)
        for a in ranges[k, 0]:
            if np.isfinite(a):
                point = x.copy()
                point[k] = a
                alike_scales.append(problem.scales(point).scale)
    if problem.fit_scale and len(alike_scales) > 1:
        # the joint std of a scale and a roughness it is degenerate with is meaningless:
        # the scales' std with the unconstrained values held, widened by their spread
        held = free & np.array([not r for r in reasons])
        _, std_scale = joint_std(
            [cols[k] for k in np.flatnonzero(held)], c, problem.likelihood, scales.scale, True
        )
        found = np.array(alike_scales)
        spread = (np.nanmax(found, axis=0) - np.nanmin(found, axis=0)) / 2
        scales.scale_std = np.hypot(std_scale, spread)
    return RoughnessFit(
        roughness=x,
        roughness_std=std,
        scales=scales,
        model=c,
        success=success,
        message=message,
        n_iterations=n_iterations,
        n_simulations=len(problem.cache),
        derivative=derivative,
        profile=profile,
        unconstrained=reasons,
        ranges=ranges,
    )


def _reason(
    value: float, std: float, derivative: float, profile: F64, flat: bool, lo: float, hi: float
) -> str:
    """Why a roughness is not constrained ("" where it is): module doc."""
    if flat:
        return "chi2 changes by less than one reduced chi2 between scan values a factor " + (
            f"{(hi / lo) ** (1 / 6):.3g} apart"
        )
    if derivative == 0 or not np.isfinite(std) or std > hi - lo:
        return (
            f"std {std:.3g} for bounds ({lo:g}, {hi:g}): changing it changes the light curve "
            "not at all or only in brightness, which the albedo absorbs"
        )
    if min(value - lo, hi - value) < 1e-6:
        return f"it stopped at a bound ({value:g})"
    if np.any(np.isfinite(profile)) and np.nanmin(profile) < 1.0:
        side = "below" if profile[0] < profile[1] else "above"
        how = "falls" if np.nanmin(profile) < 0 else "barely rises"
        return f"chi2 {how} {PROFILE_SIGMAS:g} std {side} {value:.4g}"
    return ""


def chi2_profile(problem: RoughnessProblem, alpha: F64, std: F64) -> F64:
    """Rise of chi2 at -/+ PROFILE_SIGMAS std of each roughness, in units of the reduced
    chi2 (K, 2); NaN for a side beyond a bound or an unconstrained (NaN, infinite) std.

    A quadratic minimum rises by PROFILE_SIGMAS^2 = 4 on both sides. Much less means that the
    linearised std is wrong: chi2 is flat on that side (the data give only a bound), or the
    fit stopped on a slope (negative: chi2 is lower there).
    """
    lo, hi = problem.lo, problem.hi
    best = problem.chi2(alpha)
    reduced = problem.unit(best, alpha.size)
    out = np.full((alpha.size, 2), np.nan)
    for k in range(alpha.size):
        if not np.isfinite(std[k]) or std[k] > hi - lo:
            continue
        step = max(PROFILE_SIGMAS * std[k], 10 * ROUGHNESS_RESOLUTION)
        for side, sign in enumerate((-1.0, 1.0)):
            a = alpha.copy()
            a[k] += sign * step
            if lo <= a[k] <= hi:
                out[k, side] = (problem.chi2(a) - best) / reduced
    return out


def profile_range(
    problem: RoughnessProblem, x: F64, k: int, rise: float, best: float
) -> tuple[float, float]:
    """The range of roughness k whose chi2 (the others held at ``x``) is within ``rise`` of
    ``best``: outward from ``x[k]`` over the grid of the scan, each edge located by
    bisection in log roughness (module doc). An edge that reaches a bound is that bound."""
    from speclight.estimate.fitting.roughness_scan import SCAN_POINTS

    lo, hi = problem.lo, problem.hi
    grid = np.geomspace(lo, hi, SCAN_POINTS)

    def excess(a: float) -> float:
        point = x.copy()
        point[k] = a
        return problem.chi2(point) - best - rise

    edges = []
    for outward, bound in ((grid[grid < x[k]][::-1], lo), (grid[grid > x[k]], hi)):
        inside, edge = float(x[k]), bound
        for g in outward:
            if excess(float(g)) > 0:
                edge = _bisect(excess, inside, float(g))
                break
            inside = float(g)
        edges.append(edge)
    return float(edges[0]), float(edges[1])


def _bisect(excess: Callable[[float], float], inside: float, outside: float) -> float:
    """The roughness between ``inside`` (excess <= 0) and ``outside`` (> 0) where the excess
    crosses 0: bisections in log roughness, then linear interpolation."""
    a, b = np.log(inside), np.log(outside)
    fa, fb = excess(inside), excess(outside)
    for _ in range(BISECTIONS):
        mid = 0.5 * (a + b)
        fm = excess(float(np.exp(mid)))
        if fm > 0:
            b, fb = mid, fm
        else:
            a, fa = mid, fm
    t = -fa / (fb - fa) if fb != fa else 0.5
    return float(np.exp(a + min(max(t, 0.0), 1.0) * (b - a)))


def _jacobian(
    problem: RoughnessProblem, alpha: F64, scale: F64, fd: F64 | None, free: np.ndarray
) -> tuple[list[F64], F64]:
    """d(s_j c_tj)/d alpha_k as (N, B) arrays (analytic, or central differences of half step
    ``fd``), and their size relative to the model; for the roughness values ``free`` only
    (the others: zero columns and NaN sizes)."""
    lo, hi = problem.lo, problem.hi
    c, dc = problem.evaluate(alpha)
    s = np.where(np.isfinite(scale), scale, 0.0) if problem.fit_scale else np.ones(c.shape[1])
    cols, size = [], np.full(alpha.size, np.nan)
    top = np.nanmax(np.abs(c)) if np.any(np.isfinite(c)) else 0.0
    for k in range(alpha.size):
        if not free[k]:
            cols.append(np.zeros_like(c))
            continue
        if fd is None:
            assert dc is not None
            d = dc[k]
        else:
            a, b = alpha.copy(), alpha.copy()
            a[k], b[k] = max(alpha[k] - fd[k], lo), min(alpha[k] + fd[k], hi)
            d = (problem.rates(b) - problem.rates(a)) / (b[k] - a[k])
        cols.append(d * s[None, :])
        size[k] = float(np.nanmax(np.abs(d)) / top) if top > 0 and np.any(np.isfinite(d)) else 0.0
    return cols, size


def range_text(low: float, high: float, lo: float, hi: float) -> str:
    """A profile range in words: "0.05-0.2", "up to 0.2", "from 0.3", "any value"."""
    at_lo, at_hi = low <= lo * (1 + 1e-9), high >= hi * (1 - 1e-9)
    if at_lo and at_hi:
        return f"any value in the bounds {lo:g}-{hi:g}"
    if at_lo:
        return f"{lo:g}-{high:.2g}"
    if at_hi:
        return f"{low:.2g}-{hi:g}"
    return f"{low:.2g}-{high:.2g}"


def unconstrained_text(reason: str, ranges: F64, lo: float, hi: float) -> str:
    """The message of a roughness that is not constrained: the reason, then its profile
    ranges (module doc)."""
    one, three = ranges[0], ranges[1]
    text = f"{reason}; {range_text(one[0], one[1], lo, hi)} fit within one standard deviation"
    if not np.all(np.isfinite(three)):
        return text
    three_text = range_text(three[0], three[1], lo, hi)
    if three_text.startswith("any value"):
        return text + "; no value in the bounds is excluded at three"
    return text + f"; values outside {three_text} are excluded at three standard deviations"


__all__ = [
    "BISECTIONS",
    "PROFILE_LEVELS",
    "PROFILE_SIGMAS",
    "RoughnessFit",
    "chi2_profile",
    "finish",
    "profile_range",
    "range_text",
    "unconstrained_text",
]
