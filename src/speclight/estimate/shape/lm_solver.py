"""Levenberg-Marquardt on residuals with an analytic Jacobian.

Minimises ``sum r(x)^2`` over the free entries of ``x``; each step solves
``(J^T J + lam diag(J^T J)) dx = -J^T r`` (Marquardt 1963, J. SIAM 11, 431,
doi:10.1137/0111030: the damping scaled by the diagonal, so the step does not depend on the
parameters' units), the damping divided by :data:`DOWN` after a step that lowered the sum
and multiplied by :data:`UP` (the step retried) after one that did not.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]
Residuals = Callable[[F64], tuple[F64, F64]]
UP, DOWN = 10.0, 10.0
START_DAMPING = 1e-3
MAX_DAMPING = 1e12


@dataclass(frozen=True)
class LmResult:
    """The end of a Levenberg-Marquardt run.

    Attributes
    ----------
    x
        Parameters at the end (fixed entries as given).
    cost
        ``sum r^2`` there.
    residuals, jacobian
        ``r`` and ``J`` (all parameters' columns) there.
    iterations
        Steps tried.
    converged
        True when the relative decrease of the cost fell below the tolerance.
    """

    x: F64
    cost: float
    residuals: F64
    jacobian: F64
    iterations: int
    converged: bool


def levenberg_marquardt(
    fun: Residuals,
    x0: F64,
    free: NDArray[np.bool_],
    *,
    max_iterations: int = 50,
    rtol: float = 1e-4,
) -> LmResult:
    """Minimise ``sum fun(x)[0]^2`` over ``x[free]`` (module doc).

    Parameters
    ----------
    fun
        ``x -> (r, J)``: residuals (M,) and their Jacobian (M, P) with respect to all P
        parameters.
    x0
        (P,) start.
    free
        (P,) True for the parameters that move.
    max_iterations
        Most steps tried.
    rtol
        Converged when a successful step lowers the cost by less than ``rtol`` times it.
    """
    x = np.asarray(x0, dtype=float).copy()
    r, jac = fun(x)
    cost = float(r @ r)
    lam = START_DAMPING
    converged = False
    it = 0
    idx = np.flatnonzero(free)
    for it in range(1, max_iterations + 1):
        j = jac[:, idx]
        jtj = j.T @ j
        grad = j.T @ r
        diag = np.maximum(np.diag(jtj), 1e-12 * max(float(np.max(np.diag(jtj))), 1e-300))
        while True:
            try:
                step = np.linalg.solve(jtj + lam * np.diag(diag), -grad)
            except np.linalg.LinAlgError:
                step = np.full(idx.size, np.nan)
            trial = x.copy()
            trial[idx] += step
            r_new, jac_new = fun(trial) if np.all(np.isfinite(step)) else (r, jac)
            new_cost = float(r_new @ r_new)
            if np.isfinite(new_cost) and new_cost < cost:
                break
            lam *= UP
            if lam > MAX_DAMPING:
                return LmResult(x, cost, r, jac, it, True)
        gain = (cost - new_cost) / cost if cost > 0 else 0.0
        x, r, jac, cost = trial, r_new, jac_new, new_cost
        lam = max(lam / DOWN, 1e-12)
        if gain < rtol:
            converged = True
            break
    return LmResult(x, cost, r, jac, it, converged)
