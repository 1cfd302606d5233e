"""Covariance of a least-squares fit whose residuals are correlated in time.

The linearised covariance of a least-squares estimate is the sandwich
``C = B^+ M B^+``, ``B = J^T J`` (``J`` the Jacobian of the residuals, in units of the
data's sigma), ``M`` the covariance of the score ``J^T r`` (White 1980, Econometrica 48,
817). With independent noise of the stated sigma ``M = B`` and ``C = B^-1``; model error
(a light model without some shadow, a coarse map) leaves residuals that run in one sign for
several points, and ``M`` then counts their products at neighbouring lags with Bartlett
weights ``1 - l / S`` (Newey & West 1987, Econometrica 55, 703), which keeps ``C``
positive semi-definite. The bandwidth ``S`` is Andrews' (1991, Econometrica 59, 817, eq.
6.2 and 6.4) plug-in for an AR(1) of the residuals' lag-1 correlation ``rho``:
``S = 1.1447 (alpha n)^(1/3)``, ``alpha = 4 rho^2 / ((1 - rho)^2 (1 + rho)^2)``. The
factor ``n / (n - p)`` corrects the residuals' shrinkage by the fit (MacKinnon & White
1985, J. Econometrics 29, 305: "HC1").
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.shape.tumbling_principal import lag1_correlation

F64 = NDArray[np.float64]
#: Bartlett bandwidth constant of Andrews (1991), eq. 6.2.
ANDREWS_BARTLETT = 1.1447
#: Largest lag-1 correlation used for the bandwidth (a nearly constant misfit).
MAX_RHO = 0.97


def bartlett_bandwidth(rho: float, n: int) -> float:
    """Andrews' (1991) bandwidth ``S`` [points] of the Bartlett kernel for ``n`` residuals
    of lag-1 correlation ``rho`` (module doc); lags ``l < S`` enter with ``1 - l / S``."""
    r = min(max(rho, 0.0), MAX_RHO)
    alpha = 4 * r**2 / ((1 - r) ** 2 * (1 + r) ** 2)
    return float(max(ANDREWS_BARTLETT * (alpha * n) ** (1 / 3), 1.0))


def hac_covariance(jac: F64, residuals: F64, bandwidth: float | None = None) -> F64:
    """(P, P) sandwich covariance of the parameters (module doc).

    Parameters
    ----------
    jac
        (N, P) Jacobian of the residuals at the solution, rows in time order.
    residuals
        (N,) residuals at the solution [units of the data's sigma].
    bandwidth
        Bartlett bandwidth ``S`` [points]; default :func:`bartlett_bandwidth` of the
        residuals' lag-1 correlation. ``S <= 1`` gives White's estimator (no lags).

    Returns
    -------
    numpy.ndarray
        ``B^+ M B^+ n / (n - p)`` with ``B = J^T J``.
    """
    n, p = jac.shape
    if bandwidth is None:
        bandwidth = bartlett_bandwidth(lag1_correlation(residuals), n)
    score = jac * residuals[:, None]  # (N, P): each point's contribution to J^T r
    meat = score.T @ score
    for lag in range(1, int(np.ceil(bandwidth))):
        weight = 1.0 - lag / bandwidth
        cross = score[lag:].T @ score[:-lag]
        meat += weight * (cross + cross.T)
    bread = np.linalg.pinv(jac.T @ jac)
    return np.asarray(bread @ meat @ bread * n / max(n - p, 1))


def block_jackknife_covariance(jac: F64, residuals: F64, n_blocks: int) -> F64:
    """(P, P) delete-a-block jackknife covariance, linearised (Kunsch 1989, Ann. Stat. 17,
    1217): the points in ``n_blocks`` contiguous blocks in time order; leaving block ``g``
    out moves the solution by the Gauss-Newton step ``(B - J_g^T J_g)^+ J_g^T r_g``, and
    the covariance is ``(G - 1) / G`` times the sum of the steps' outer products about
    their mean."""
    bread = jac.T @ jac
    steps = []
    for idx in np.array_split(np.arange(len(residuals)), n_blocks):
        jg = jac[idx]
        steps.append(np.linalg.pinv(bread - jg.T @ jg) @ (jg.T @ residuals[idx]))
    d = np.array(steps) - np.mean(steps, axis=0)
    return np.asarray((n_blocks - 1) / n_blocks * d.T @ d)

