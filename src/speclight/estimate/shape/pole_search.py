"""Pole search: a chi-square map on a grid in ecliptic (lambda, beta), then LM refinement.

At every grid pole the areas and the period are fitted with the pole held (the map); the
:data:`N_REFINE` lowest distinct minima of the map and the mirror of the best,
``(lambda + 180 deg, beta)``, are then refined with everything free (Levenberg-Marquardt with
the analytic Jacobian of :mod:`.convex_model`). The mirror: for observations near the
ecliptic plane, ``(lambda, beta)`` and ``(lambda + 180 deg, beta)`` give the same light curves
with mirrored shapes (Kaasalainen & Lamberg 2006, in "Inverse Problems in Vision and 3D
Tomography"; Kaasalainen, Torppa & Muinonen 2001, sec. 4), so it is always refined and
reported beside the best.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.estimate.shape.convex_fit import ConvexSolution, fit_convex
from speclight.estimate.shape.convex_model import ConvexModel
from speclight.estimate.shape.ecliptic import angular_distance_deg, pole_vector
from speclight.progress import stage

F64 = NDArray[np.float64]
N_REFINE = 3
#: Two map minima closer than this are one [deg].
DISTINCT_DEG = 30.0
MAP_ITERATIONS = 30


def pole_grid(step_deg: float) -> tuple[F64, F64]:
    """Grid longitudes ``[0, 360)`` and latitudes ``(-90, 90)`` (cell centres) [deg].

    Raises
    ------
    InputError
        For a step outside (0, 90] (field ``pole_step_deg``).
    """
    if not (0 < step_deg <= 90):
        raise InputError(f"pole_step_deg = {step_deg} must be in (0, 90]", field="pole_step_deg")
    n_lat = int(np.ceil(180.0 / step_deg))
    n_lon = int(np.ceil(360.0 / step_deg))
    beta = -90.0 + (np.arange(n_lat) + 0.5) * 180.0 / n_lat
    lam = np.arange(n_lon) * 360.0 / n_lon
    return lam, beta


@dataclass(frozen=True)
class PoleSearch:
    """Result of :func:`search_poles`.

    Attributes
    ----------
    lambda_deg, beta_deg
        (L,), (B,) the grid [deg].
    chi2
        (B, L) chi-square with the pole held at each grid point.
    solutions
        Refined solutions, lowest chi-square first (the best, then others).
    mirror
        The refined mirror of the best solution.
    """

    lambda_deg: F64
    beta_deg: F64
    chi2: F64
    solutions: list[ConvexSolution]
    mirror: ConvexSolution


def search_poles(
    model: ConvexModel,
    period_h: float,
    *,
    step_deg: float = 30.0,
    max_iterations: int = MAP_ITERATIONS,
    progress: bool = False,
) -> PoleSearch:
    """The pole map and its refined minima (module doc)."""
    lam, bet = pole_grid(step_deg)
    chi2 = np.full((bet.size, lam.size), np.inf)
    period = np.full_like(chi2, period_h)
    with stage("pole map", total=chi2.size, enabled=progress) as tick:
        for i, b in enumerate(bet):
            for j, la in enumerate(lam):
                sol = fit_convex(
                    model, la, b, period_h, free_pole=False, max_iterations=max_iterations
                )
                chi2[i, j], period[i, j] = sol.chi2, sol.period_h
                tick(1)
    starts = _distinct_minima(lam, bet, chi2, N_REFINE)
    refined = [fit_convex(model, la, b, period[i, j]) for (la, b, i, j) in starts]
    refined.sort(key=lambda s: s.chi2)
    best = refined[0]
    mirror = fit_convex(model, best.lambda_deg + 180.0, best.beta_deg, best.period_h)
    return PoleSearch(lam, bet, chi2, refined, mirror)


def _distinct_minima(lam: F64, bet: F64, chi2: F64, n: int) -> list[tuple[float, float, int, int]]:
    """Up to ``n`` grid cells of lowest chi-square, each at least :data:`DISTINCT_DEG` from
    those taken before."""
    order = np.argsort(chi2, axis=None)
    taken: list[tuple[float, float, int, int]] = []
    for flat in order:
        i, j = np.unravel_index(flat, chi2.shape)
        v = pole_vector(lam[j], bet[i])
        if all(angular_distance_deg(v, pole_vector(t[0], t[1])) >= DISTINCT_DEG for t in taken):
            taken.append((float(lam[j]), float(bet[i]), int(i), int(j)))
        if len(taken) == n or not np.isfinite(chi2[i, j]):
            break
    return taken


def pole_distance_deg(sol: ConvexSolution, lambda_deg: float, beta_deg: float) -> float:
    """Angle between a solution's pole and ``(lambda_deg, beta_deg)`` [deg]."""
    return float(
        angular_distance_deg(
            pole_vector(sol.lambda_deg, sol.beta_deg), pole_vector(lambda_deg, beta_deg)
        )
    )


def distinct_solutions(solutions: list[ConvexSolution]) -> list[ConvexSolution]:
    """Lowest chi-square first, each at least :data:`DISTINCT_DEG` from the poles kept before
    it (fits from different starts that ended in one minimum count once)."""
    kept: list[ConvexSolution] = []
    for s in sorted(solutions, key=lambda s: s.chi2):
        if all(pole_distance_deg(s, k.lambda_deg, k.beta_deg) >= DISTINCT_DEG for k in kept):
            kept.append(s)
    return kept


def nearest_solution(
    solutions: list[ConvexSolution], lambda_deg: float, beta_deg: float
) -> ConvexSolution | None:
    """The lowest-chi-square solution within :data:`DISTINCT_DEG` of ``(lambda_deg,
    beta_deg)``, or None."""
    near = [s for s in solutions if pole_distance_deg(s, lambda_deg, beta_deg) < DISTINCT_DEG]
    return min(near, key=lambda s: s.chi2) if near else None
