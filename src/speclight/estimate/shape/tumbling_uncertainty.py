"""Standard deviations of a fitted torque-free state: rate, moment ratios, momentum direction.

The fit's Jacobian ``J`` (residuals in units of the data's sigma over the state vector:
rotation vector, body rates [rad/s], second-moment parameters ``u``, log scale) and
residuals ``r`` at the solution give the parameters' linearised covariance ``C``, as one
of three base estimates (:data:`CovarianceMethod`):

* ``"jackknife"`` (the default): delete-a-block jackknife, linearised (Kunsch 1989, Ann.
  Stat. 17, 1217): the points in :data:`JACKKNIFE_BLOCKS` contiguous blocks in time order;
  leaving block ``g`` out moves the solution by the Gauss-Newton step
  ``(B - J_g^T J_g)^+ J_g^T r_g``, ``B = J^T J``; ``C`` is ``(G - 1) / G`` times the sum
  of the steps' outer products about their mean. Runs of residuals of one sign (model
  error) shorter than a block are counted whatever their correlation's shape, and a block
  that pulls the solution counts by its own leverage.
* ``"sandwich"``: ``B^+ M B^+`` with ``M`` the covariance of the score ``J^T r`` (White
  1980, Econometrica 48, 817) counted over neighbouring lags with Bartlett weights
  ``1 - l / S`` (Newey & West 1987, Econometrica 55, 703), ``S`` Andrews' (1991,
  Econometrica 59, 817, eq. 6.2 and 6.4) plug-in for an AR(1) of the residuals' lag-1
  correlation ``rho``: ``S = 1.1447 (alpha n)^(1/3)``, ``alpha = 4 rho^2 / ((1 - rho)^2
  (1 + rho)^2)``; times ``n / (n - p)`` (MacKinnon & White 1985, J. Econometrics 29, 305).
* ``"scalar"`` (the earlier estimate): ``s^2 B^+``, ``s^2 = chi2 / (n - p)`` times
  ``(1 + rho) / (1 - rho)`` (fewer independent points; Bartlett 1946, J. R. Stat. Soc.
  Suppl. 8, 27).

**Model-error term.** Every residual-based estimate sees only what the fit leaves: where
the light model is wrong (a map's interpolation, shadows a convex model lacks) the part of
the misfit that looks like a change of state is absorbed into the state, biasing it, and
is missing from the residuals. On rendered light curves fitted with the reflectivity map
every residual-based estimate above came out 1.5-2.7 times too small (BENCHMARKS.md,
"Tumbling uncertainty"). So the base estimate is multiplied by ``1 + w f``, ``f`` the
share of the chi-square above the noise floor (:func:`excess_share`: 0 when the residuals
are the stated noise, so noise alone keeps the base estimate) and ``w`` =
:data:`MODEL_ERROR_WEIGHT`, calibrated over blind draws (``bench/bench_calibration_tumbling.py``:
tuned on 200 random states of the box-wing with its map, checked on 60 others).

The summary (:func:`state_summary`): the rate ``|H| / I_max`` [rad/s], the sorted moment
ratios, and the unit angular momentum's components along the local east (increasing
ecliptic longitude) and north at the solution's own direction [rad, small angles]; their
standard deviations follow from ``C`` through central differences of the summary.
"""

from __future__ import annotations

from typing import Literal, get_args

import numpy as np
from numpy.typing import NDArray
from scipy import stats
from scipy.spatial.transform import Rotation

from speclight.attitude.quaternion import quat_rotate
from speclight.errors import InputError
from speclight.estimate.shape.tumbling_principal import lag1_correlation
from speclight.estimate.shape.tumbling_search import moments_from_u

F64 = NDArray[np.float64]
CovarianceMethod = Literal["sandwich", "jackknife", "scalar"]
#: Bartlett bandwidth constant of Andrews (1991), eq. 6.2.
ANDREWS_BARTLETT = 1.1447
#: Largest lag-1 correlation used for the bandwidth (a nearly constant misfit).
MAX_RHO = 0.97
#: Contiguous blocks of the delete-a-block jackknife.
JACKKNIFE_BLOCKS = 20
#: Weight of the model-error term (module doc).
MODEL_ERROR_WEIGHT = 2.0
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
    elif method == "scalar":
        rho = max(lag1_correlation(residuals), 0.0)
        s2 = float(np.sum(residuals**2)) / max(n - p, 1) * (1 + rho) / (1 - rho)
        cov = s2 * np.linalg.pinv(jac.T @ jac)
    else:
        raise InputError(
            f"method = {method!r} is not a covariance method; choose one of "
            f"{', '.join(get_args(CovarianceMethod))}",
            field="method",
        )
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
