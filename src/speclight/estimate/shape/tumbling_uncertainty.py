"""Standard deviations of a fitted torque-free state's rate and moment ratios.

The fit's Jacobian ``J`` (residuals over the state vector: rotation vector, body rates
[rad/s], second-moment parameters ``u``, log scale) gives the linearised covariance
``C = s^2 (J^T J)^+``, ``s^2`` the residual variance ``chi2 / (n - p)`` times
``(1 + rho) / (1 - rho)``, ``rho`` the residuals' lag-1 correlation (model error, such as
the shadows a convex model lacks, leaves runs of residuals of one sign: fewer independent
points; Bartlett 1946, J. R. Stat. Soc. Suppl. 8, 27). The rate ``|H| / I_max`` and the
sorted moment ratios are functions of the body rates and ``u`` alone; their standard
deviations follow from ``C`` through central differences of those functions.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.shape.tumbling_principal import lag1_correlation
from speclight.estimate.shape.tumbling_search import moments_from_u

F64 = NDArray[np.float64]
#: Step of the central differences of the rate [relative] and of ``u`` [1].
STEP = 1e-6


def rate_and_ratios(x: F64) -> F64:
    """``(|H| / I_max [rad/s], smaller moment ratio, middle one)`` of a state vector."""
    moments = moments_from_u(x[6:8])
    m = np.sort(moments)
    rate = np.linalg.norm(moments * x[3:6]) / m[2]
    return np.array([rate, m[0] / m[2], m[1] / m[2]])


def rate_and_ratio_std(x: F64, jac: F64, residuals: F64) -> F64:
    """(3,) standard deviations of :func:`rate_and_ratios` at the solution ``x`` (module
    doc); ``jac`` (N, P) and ``residuals`` (N,) at ``x`` (``P`` its first parameters)."""
    n, p = jac.shape
    rho = max(lag1_correlation(residuals), 0.0)
    s2 = float(np.sum(residuals**2)) / max(n - p, 1) * (1 + rho) / (1 - rho)
    cov = s2 * np.linalg.pinv(jac.T @ jac)
    grad = np.zeros((3, p))
    rate_step = STEP * float(np.linalg.norm(x[3:6]))
    for k in range(3, 8):
        h = STEP * max(abs(float(x[k])), 1.0) if k >= 6 else max(rate_step, 1e-18)
        up, down = x.copy(), x.copy()
        up[k] += h
        down[k] -= h
        grad[:, k] = (rate_and_ratios(up) - rate_and_ratios(down)) / (2 * h)
    return np.sqrt(np.maximum(np.diag(grad @ cov @ grad.T), 0.0))
