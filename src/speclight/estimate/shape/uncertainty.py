"""Uncertainty of a convex solution: covariance, bootstrap, mirror pole, null tests.

* Covariance: ``s^2 (J^T J)^-1`` at the solution (Laplace approximation of the posterior
  for Gaussian noise; Press et al., Numerical Recipes, 3rd ed., sec. 15.5), with the
  penalty rows included and ``s^2 = chi2 / (N - p)`` (the residuals' own scale: DAMIT files
  carry no sigmas, and a model error is absorbed the same way; ``p`` the effective number of
  parameters, :func:`effective_dof`). The pole's ``sigma_pole``
  is ``sqrt(sigma_beta^2 + cos^2 beta sigma_lambda^2)`` [deg].
* Bootstrap: each draw resamples the points of every light curve with replacement
  (Efron & Tibshirani 1993, ch. 6) and refits from the solution; the spread of the draws.
* Mirror: the mirror pole is reported when its chi-square is within
  :data:`MIRROR_DELTA` ``s^2`` of the best (the 99 % point of chi-square with 2 degrees of
  freedom: the data cannot tell the two poles apart).
* Null tests: the data constrain a shape when the fit beats a sphere (no light-curve
  shape, only the phase-angle trend) by an F-test at :data:`NULL_P_VALUE`; they constrain the
  pole when the pole map's chi-square spans more than :data:`POLE_DELTA` ``s^2`` (the 99.9 %
  point for 2 degrees of freedom), the period when the scan's median chi-square is more
  than that above its minimum.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import stats

from speclight.estimate.shape.convex_fit import ConvexSolution, fit_convex
from speclight.estimate.shape.convex_model import N_ROTATION, ConvexModel

F64 = NDArray[np.float64]
MIRROR_DELTA = float(stats.chi2.ppf(0.99, 2))
POLE_DELTA = float(stats.chi2.ppf(0.999, 2))
NULL_P_VALUE = 1e-3
BOOTSTRAP_ITERATIONS = 20


@dataclass(frozen=True)
class Covariance:
    """Standard deviations of a solution from its Jacobian.

    Attributes
    ----------
    lambda_deg, beta_deg, period_h
        Standard deviations of the pole longitude and latitude [deg] and the period [h].
    pole_deg
        ``sqrt(sigma_beta^2 + cos^2 beta sigma_lambda^2)`` [deg].
    log_area
        (K,) standard deviations of the log-areas [1] (relative area errors).
    residual_scale
        ``s = sqrt(chi2 / (N - p))``.
    """

    lambda_deg: float
    beta_deg: float
    period_h: float
    pole_deg: float
    log_area: F64
    residual_scale: float


def _unscaled_covariance(model: ConvexModel, sol: ConvexSolution) -> tuple[F64, float]:
    """``(J^T J)^-1`` (penalty rows included) and the effective number of parameters the
    data fit, ``tr(J_d (J^T J)^-1 J_d^T)`` over the data rows ``J_d`` (the trace of the hat
    matrix; Hastie, Tibshirani & Friedman 2009, sec. 7.6): below the nominal count where
    the penalties hold some directions (the closure, the scale)."""
    _, jac = model.residuals(sol.theta)
    cov = np.asarray(np.linalg.pinv(jac.T @ jac), dtype=np.float64)
    data_rows = jac[: model.data.n_points]
    return cov, float(np.sum((data_rows @ cov) * data_rows))


def effective_dof(model: ConvexModel, sol: ConvexSolution) -> tuple[float, float]:
    """``(p_eff, N - p_eff)``: the fit's effective parameters and residual degrees of
    freedom."""
    _, p_eff = _unscaled_covariance(model, sol)
    return p_eff, max(model.data.n_points - p_eff, 1.0)


def covariance(model: ConvexModel, sol: ConvexSolution) -> Covariance:
    """Laplace covariance at ``sol`` (module doc)."""
    cov, p_eff = _unscaled_covariance(model, sol)
    s2 = sol.chi2 / max(model.data.n_points - p_eff, 1.0)
    cov = cov * s2
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    lam, bet = np.rad2deg(sd[0]), np.rad2deg(sd[1])
    pole = float(np.hypot(bet, np.cos(sol.theta[1]) * lam))
    return Covariance(
        float(lam), float(bet), float(sd[2]), pole, sd[N_ROTATION:], float(np.sqrt(s2))
    )


def bootstrap(model: ConvexModel, sol: ConvexSolution, draws: int, seed: int) -> F64:
    """(draws, 3) bootstrap ``(lambda [deg], beta [deg], P [h])`` (module doc)."""
    rng = np.random.default_rng(seed)
    d = model.data
    out = np.empty((draws, 3))
    runs = [np.flatnonzero(d.curve == c) for c in range(d.n_curves)]
    for k in range(draws):
        idx = np.sort(np.concatenate([rng.choice(r, r.size) for r in runs]))
        sub = ConvexModel(d.subset(idx), model.normals, model.law, model.t0_jd)
        fit = fit_convex(
            sub,
            sol.lambda_deg,
            sol.beta_deg,
            sol.period_h,
            log_areas=sol.theta[N_ROTATION:],
            max_iterations=BOOTSTRAP_ITERATIONS,
        )
        lam = fit.lambda_deg
        # keep the longitude on the same branch as the solution's
        out[k] = (
            sol.lambda_deg + ((lam - sol.lambda_deg + 180.0) % 360.0 - 180.0),
            fit.beta_deg,
            fit.period_h,
        )
    return out


def sphere_chi2(model: ConvexModel) -> float:
    """Chi-square of a sphere (equal areas; its brightness follows the phase angle only),
    with the best scale for calibrated curves."""
    k = len(model.normals)
    theta = np.concatenate([[0.0, np.pi / 2, 1.0], np.zeros(k)])
    lum, _ = model.brightness(theta)
    d = model.data
    cal = d.calibrated[d.curve]
    if np.any(cal):
        w = 1.0 / d.sigma[cal] ** 2
        scale = np.sum(w * lum[cal] * d.brightness[cal]) / np.sum(w * lum[cal] ** 2)
        theta[N_ROTATION:] = np.log(scale)
    return model.chi2(theta)


def shape_p_value(model: ConvexModel, sol: ConvexSolution) -> float:
    """F-test p-value of the fit against the sphere (small: the data constrain a shape)."""
    p, dof = effective_dof(model, sol)
    chi0 = sphere_chi2(model)
    f = ((chi0 - sol.chi2) / p) / (sol.chi2 / dof)
    return float(stats.f.sf(f, p, dof)) if np.isfinite(f) else 1.0


def mirror_ambiguous(best: ConvexSolution, mirror: ConvexSolution, scale: float) -> bool:
    """True when the mirror's chi-square is within :data:`MIRROR_DELTA` ``s^2`` of the best."""
    return bool(mirror.chi2 - best.chi2 <= MIRROR_DELTA * scale**2)


def spans(chi2: F64, scale: float, reference: str = "max") -> bool:
    """True when ``chi2`` rises above its minimum by more than :data:`POLE_DELTA` ``s^2``
    (to its maximum, or to its median with ``reference="median"``)."""
    finite = chi2[np.isfinite(chi2)]
    if finite.size < 2:
        return False
    top = np.max(finite) if reference == "max" else np.median(finite)
    return bool(top - np.min(finite) > POLE_DELTA * scale**2)
