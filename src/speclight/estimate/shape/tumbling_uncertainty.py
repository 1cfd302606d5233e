"""Standard deviations of a fitted torque-free state: rate, moment ratios, momentum direction.

The fit's Jacobian ``J`` (residuals over the state vector: rotation vector, body rates
[rad/s], second-moment parameters ``u``, log scale) and residuals ``r`` at the solution
give the parameters' linearised covariance ``C`` two ways:

* ``"sandwich"`` (the default): :func:`.hac_covariance.hac_covariance`, ``(J^T J)^+ M
  (J^T J)^+`` with ``M`` the score's covariance counted over neighbouring lags (Newey &
  West 1987). Model error (shadows a convex model lacks, a map's interpolation) leaves runs
  of residuals of one sign whose effect differs from parameter to parameter; the sandwich
  weighs them by each parameter's own Jacobian.
* ``"scalar"`` (the earlier estimate): ``s^2 (J^T J)^+``, ``s^2 = chi2 / (n - p)`` times
  ``(1 + rho) / (1 - rho)``, ``rho`` the residuals' lag-1 correlation (fewer independent
  points; Bartlett 1946, J. R. Stat. Soc. Suppl. 8, 27), the same factor for every
  parameter.

The summary (:func:`state_summary`): the rate ``|H| / I_max`` [rad/s], the sorted moment
ratios, and the unit angular momentum's components along the local east (increasing
ecliptic longitude) and north at the solution's own direction [rad, small angles]; their
standard deviations follow from ``C`` through central differences of the summary.
Calibration over blind noise draws: BENCHMARKS.md, "Tumbling uncertainty".
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.typing import NDArray
from scipy import stats
from scipy.spatial.transform import Rotation

from speclight.attitude.quaternion import quat_rotate
from speclight.estimate.shape.hac_covariance import block_jackknife_covariance, hac_covariance
from speclight.estimate.shape.tumbling_principal import lag1_correlation
from speclight.estimate.shape.tumbling_search import moments_from_u

F64 = NDArray[np.float64]
CovarianceMethod = Literal["sandwich", "jackknife", "scalar"]
#: Contiguous blocks of the delete-a-block jackknife.
JACKKNIFE_BLOCKS = 20
#: Weight of the model-error term (module doc).
MODEL_ERROR_WEIGHT = 1.0
#: Step of the central differences: of the rotation vector [rad], the rates [relative] and
#: ``u`` [1].
STEP = 1e-6
#: Names of the summary's entries, in order (SHAPE.nc: ``tumbling_*_std``).
SUMMARY = ("rate", "ratio_small", "ratio_middle", "momentum_east", "momentum_north")


def momentum_basis(direction: F64) -> tuple[F64, F64]:
    """Unit east and north vectors (ecliptic J2000) at the unit ``direction``; at a pole,
    east is +x."""
    east = np.cross([0.0, 0.0, 1.0], direction)
    norm = float(np.linalg.norm(east))
    east = east / norm if norm > 1e-12 else np.array([1.0, 0.0, 0.0])
    return east, np.cross(direction, east)


def momentum_direction(x: F64) -> F64:
    """Unit angular momentum (ecliptic J2000) of a state vector."""
    q0 = Rotation.from_rotvec(x[:3]).as_quat(scalar_first=True)
    h = quat_rotate(q0, moments_from_u(x[6:8]) * x[3:6])
    return np.asarray(h / np.linalg.norm(h))


def state_summary(x: F64, east: F64, north: F64) -> F64:
    """(5,) :data:`SUMMARY` of a state vector: ``|H| / I_max`` [rad/s], the smaller and
    the middle moment ratio, the momentum direction's components along ``east`` and
    ``north`` [1]."""
    moments = moments_from_u(x[6:8])
    m = np.sort(moments)
    rate = np.linalg.norm(moments * x[3:6]) / m[2]
    h = momentum_direction(x)
    return np.array([rate, m[0] / m[2], m[1] / m[2], h @ east, h @ north])


def excess_share(residuals: F64, n_par: int) -> float:
    """Share of the chi-square above the noise floor: ``max(0, 1 - q / chi2)``, ``q`` the
    99 % point of chi-square with ``n - n_par`` degrees of freedom (0 where the residuals
    are the stated noise)."""
    chi2 = float(np.sum(residuals**2))
    floor = float(stats.chi2.ppf(0.99, max(len(residuals) - n_par, 1)))
    return max(0.0, 1.0 - floor / chi2) if chi2 > 0 else 0.0


def parameter_covariance(
    jac: F64,
    residuals: F64,
    method: CovarianceMethod = "jackknife",
    model_error_weight: float = MODEL_ERROR_WEIGHT,
) -> F64:
    """(P, P) linearised covariance of the state vector (module doc); ``jac`` (N, P) and
    ``residuals`` (N,) at the solution, in time order; the base estimate times
    ``1 + model_error_weight f``, ``f`` the :func:`excess_share`."""
    n, p = jac.shape
    if method == "sandwich":
        cov = hac_covariance(jac, residuals)
    elif method == "jackknife":
        cov = block_jackknife_covariance(jac, residuals, min(JACKKNIFE_BLOCKS, n))
    else:
        rho = max(lag1_correlation(residuals), 0.0)
        s2 = float(np.sum(residuals**2)) / max(n - p, 1) * (1 + rho) / (1 - rho)
        cov = s2 * np.linalg.pinv(jac.T @ jac)
    return np.asarray(cov * (1.0 + model_error_weight * excess_share(residuals, p)))


def state_std(
    x: F64,
    jac: F64,
    residuals: F64,
    method: CovarianceMethod = "jackknife",
    model_error_weight: float = MODEL_ERROR_WEIGHT,
) -> F64:
    """(5,) standard deviations of :func:`state_summary` at the solution ``x`` (module
    doc): the rate [rad/s], the two moment ratios [1], the momentum direction along east
    and north [rad]; ``jac`` (N, P) and ``residuals`` (N,) at ``x`` (``P`` its first
    parameters)."""
    p = jac.shape[1]
    cov = parameter_covariance(jac, residuals, method, model_error_weight)
    east, north = momentum_basis(momentum_direction(x))
    grad = np.zeros((len(SUMMARY), p))
    rate_step = STEP * float(np.linalg.norm(x[3:6]))
    for k in range(8):
        if k < 3:
            h = STEP
        elif k < 6:
            h = max(rate_step, 1e-18)
        else:
            h = STEP * max(abs(float(x[k])), 1.0)
        up, down = x.copy(), x.copy()
        up[k] += h
        down[k] -= h
        grad[:, k] = (state_summary(up, east, north) - state_summary(down, east, north)) / (2 * h)
    return np.sqrt(np.maximum(np.diag(grad @ cov @ grad.T), 0.0))


#: The name :mod:`.tumbling` calls (it now also gives the momentum direction's).
rate_and_ratio_std = state_std
