"""Levenberg-Marquardt on residuals with an analytic Jacobian.

Minimises ``sum r(x)^2`` over the free entries of ``x``; each step solves
``(J^T J + lam D) dx = -J^T r`` with ``D = diag(J^T J)`` (Marquardt 1963, J. SIAM 11, 431,
doi:10.1137/0111030: the damping scaled by the diagonal, so the step does not depend on the
parameters' units). The damping follows the gain ratio ``rho`` of the actual to the
predicted decrease (Nielsen 1999, IMM-REP-1999-05; Madsen, Nielsen & Tingleff 2004,
"Methods for non-linear least squares problems", eq. 3.16): after a step that lowered the
sum ``lam *= max(1/3, 1 - (2 rho - 1)^3)``, after one that did not ``lam *= nu`` and
``nu *= 2``. A step that fails costs only the residuals: the Jacobian is computed for the
steps taken (``fun`` returns it as a function).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]
#: ``x -> (r, J)``: residuals now, their Jacobian (all parameters' columns) on demand.
Residuals = Callable[[F64], tuple[F64, Callable[[], F64]]]
START_DAMPING = 1e-3
MAX_DAMPING = 1e12
MIN_DAMPING = 1e-12
#: Successive small steps that end a run.
SMALL_STEPS = 2


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
        Steps taken (failed trial steps not counted).
    converged
        True when the relative decrease of the cost fell below the tolerance.
    evaluations
        Residual evaluations, failed trial steps included.
    """

    x: F64
    cost: float
    residuals: F64
    jacobian: F64
    iterations: int
    converged: bool
    evaluations: int = 0


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
        ``x -> (r, jacobian)``: residuals (M,) and a function returning their Jacobian
        (M, P) with respect to all P parameters.
    x0
        (P,) start.
    free
        (P,) True for the parameters that move.
    max_iterations
        Most steps taken.
    rtol
        Converged when :data:`SMALL_STEPS` successive steps each lower the cost by less
        than ``rtol`` times it (one such step can follow a damping raised by a failed
        trial, well before the minimum).
    """
    x = np.asarray(x0, dtype=float).copy()
    r, jac_of = fun(x)
    jac = jac_of()
    cost = float(r @ r)
    lam, nu = START_DAMPING, 2.0
    converged = False
    it = evaluations = small = 0
    idx = np.flatnonzero(free)
    every = idx.size == x.size
    for it in range(1, max_iterations + 1):
        jtj_all, grad_all = jac.T @ jac, jac.T @ r
        jtj = jtj_all if every else jtj_all[np.ix_(idx, idx)]
        grad = grad_all if every else grad_all[idx]
        diag = np.maximum(np.diag(jtj), 1e-12 * max(float(np.max(np.diag(jtj))), 1e-300))
        while True:
            try:
                step = np.linalg.solve(jtj + lam * np.diag(diag), -grad)
            except np.linalg.LinAlgError:
                step = np.full(idx.size, np.nan)
            new_cost, trial = np.inf, x
            if np.all(np.isfinite(step)):
                trial = x.copy()
                trial[idx] += step
                r_new, jac_new_of = fun(trial)
                evaluations += 1
                with np.errstate(over="ignore"):  # a wild trial step: inf, rejected below
                    new_cost = float(r_new @ r_new)
            if np.isfinite(new_cost) and new_cost < cost:
                break
            lam *= nu
            nu *= 2.0
            if lam > MAX_DAMPING:
                return LmResult(x, cost, r, jac, it - 1, True, evaluations)
        predicted = float(step @ (lam * diag * step - grad))
        rho = (cost - new_cost) / predicted if predicted > 0 else 1.0
        gain = (cost - new_cost) / cost if cost > 0 else 0.0
        x, r, cost = trial, r_new, new_cost
        jac = jac_new_of()
        lam = max(lam * max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3), MIN_DAMPING)
        nu = 2.0
        small = small + 1 if gain < rtol else 0
        if small >= SMALL_STEPS:
            converged = True
            break
    return LmResult(x, cost, r, jac, it, converged, evaluations)
