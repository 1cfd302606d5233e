"""Where the roughness fit starts its local method: a coordinate scan over log roughness.

Far from its minimum, chi-square over a roughness is nearly flat (a glint that does not
overlap the measured one misfits by about as much whatever its width) or slopes the wrong
way, and a local method started there stalls or runs to a bound (issue 25: a cube of four
glinting faces, every face started at 0.3 stayed there). So the fit first scans: for each
rough material in turn, the :data:`SCAN_POINTS` log-spaced values over the bounds are
simulated with the other materials held where they are, and the material moves to the best
of them (a coordinate search, the scales re-fitted at every point); sweeps over the
materials repeat until one moves none (at most :data:`MAX_SWEEPS`). Each sweep costs
``K x (SCAN_POINTS - 1)`` simulations for K materials (one of the values is the current
one); glints of different faces fall at different epochs, so the materials hardly interact
and two sweeps usually suffice. The local method then starts from the scan's best point,
within a factor ``(hi / lo)^(1 / (SCAN_POINTS - 1))`` (2.15) of the minimum, inside the
range from which both local methods converge (docs/fit.md, "From how far each method
converges").

The last sweep is a profile of chi-square over each material's grid, the others held at the
scan's best: a material whose chi-square at both grid neighbours of its best value is within
one reduced chi-square of it is **flat** (``Scan.flat``). The fit refines every material
nonetheless and judges what is constrained at its end (:mod:`.roughness_uncertainty`): far
from the minimum, a misfit of another material inflates the reduced chi-square and makes a
material look flat that is not.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.fitting.fit import F64
from speclight.estimate.fitting.roughness_problem import RoughnessProblem

#: Roughness values scanned per material, log-spaced over the bounds.
SCAN_POINTS = 7
#: Sweeps over the materials, at most.
MAX_SWEEPS = 4


@dataclass
class Scan:
    """Result of :func:`coordinate_scan`.

    Attributes
    ----------
    best
        (K,) the best roughness values found (the start where nothing scanned is better).
    grid
        (G,) the scanned values [1].
    profile
        (K, G) chi2 with material k at each grid value, the others at ``best``.
    flat
        (K,) chi2 at both grid neighbours of ``best[k]`` is within one reduced chi2.
    sweeps
        Sweeps run.
    """

    best: F64
    grid: F64
    profile: F64
    flat: NDArray[np.bool_]
    sweeps: int


def coordinate_scan(
    problem: RoughnessProblem, start: F64, points: int = SCAN_POINTS, sweeps: int = MAX_SWEEPS
) -> Scan:
    """Coordinate search of chi2 over a log grid of each roughness (module doc).

    Parameters
    ----------
    problem
        The objective (:class:`~.roughness_problem.RoughnessProblem`).
    start
        (K,) the roughness values to start from (inside the bounds).
    points
        Grid values per material, log-spaced over the bounds.
    sweeps
        Sweeps over the materials, at most.
    """
    grid = scan_grid(problem, points)
    x = np.clip(np.asarray(start, dtype=float), problem.lo, problem.hi)
    best = problem.chi2(x)
    n_sweeps = 0
    for n_sweeps in range(1, sweeps + 1):  # noqa: B007 (the count is returned)
        moved = False
        for k in range(x.size):
            values = _along(problem, x, k, grid)
            j = int(np.argmin(values))
            if values[j] < best - 1e-12 * abs(best):
                x[k], best, moved = grid[j], float(values[j]), True
        if not moved:
            break
    profile = np.array([_along(problem, x, k, grid) for k in range(x.size)])
    unit = problem.unit(best, x.size)
    flat = np.zeros(x.size, dtype=bool)
    for k in range(x.size):
        below, above = profile[k][grid < x[k]], profile[k][grid > x[k]]
        near = [v[-1] for v in (below,) if v.size] + [v[0] for v in (above,) if v.size]
        flat[k] = bool(near) and all(v - best < unit for v in near)
    return Scan(x, grid, profile, flat, n_sweeps)


def scan_grid(problem: RoughnessProblem, points: int = SCAN_POINTS) -> F64:
    """The ``points`` roughness values of the scans, log-spaced over the bounds [1]."""
    return np.geomspace(problem.lo, problem.hi, points)


def common_start(problem: RoughnessProblem, n: int, points: int = SCAN_POINTS) -> F64:
    """The best point of the common line of ``n`` roughness values: all at one of the
    ``points`` values of :func:`scan_grid` (:func:`coordinate_scan`'s grid); where a fit from
    another start misfits, the fit starts again there (:func:`.roughness_fit.solve`)."""
    grid = scan_grid(problem, points)
    values = [problem.chi2(np.full(n, g)) for g in grid]
    return np.full(n, grid[int(np.argmin(values))])


def _along(problem: RoughnessProblem, x: F64, k: int, grid: F64) -> F64:
    """chi2 with roughness k at each grid value, the others at ``x``."""
    out = np.empty(grid.size)
    for j, g in enumerate(grid):
        a = x.copy()
        a[k] = g
        out[j] = problem.chi2(a)
    return out


__all__ = ["MAX_SWEEPS", "SCAN_POINTS", "Scan", "common_start", "coordinate_scan", "scan_grid"]
