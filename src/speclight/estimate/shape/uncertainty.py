"""Uncertainty of a convex solution: covariance, bootstrap, mirror pole, null tests.

* Covariance: ``s^2 (J^T J)^-1`` at the solution (Laplace approximation of the posterior
  for Gaussian noise; Press et al., Numerical Recipes, 3rd ed., sec. 15.5), with the
  penalty rows included and ``s^2 = chi2 / (N - p)`` (the residuals' own scale: DAMIT files
  carry no sigmas, and a model error is absorbed the same way; ``p`` the effective number of
  parameters, :func:`effective_dof`). The pole's ``sigma_pole``
  is ``sqrt(sigma_beta^2 + cos^2 beta sigma_lambda^2)`` [deg].
* Bootstrap: each draw resamples the points of every light curve with replacement
  (Efron & Tibshirani 1993, ch. 6) and refits pole, period and facet areas from the
  solution; the spread of the draws. It stands in for posterior samples (MCMC, e.g. emcee):
  the residuals of real light curves are mostly model error, so a likelihood from their
  scale would have to assume noise they are not, while resampling carries whatever they
  are; and a sampler over the 3 + K parameters (K = 192 facets) needs of the order of 10^5
  to 10^6 model evaluations where a draw here needs 20 fit steps.
* Mirror (and any other pole minimum): reported beside the best when its chi-square is
  within ``max(MIRROR_DELTA, sqrt(nu / 2)) s^2`` of the best (``nu = N - p``): the 99 %
  point of chi-square with 2 degrees of freedom (:data:`MIRROR_DELTA`) where the residuals
  are the noise, and half the chi-square's own standard deviation ``sqrt(2 nu)`` (in units of
  ``s^2``) where many points make that bound tighter than the model can be trusted: on real
  light curves the residuals are mostly model error (a convex, ideal-scattering body), not
  noise. In relative terms the bound is ``0.5 sqrt(2 / nu) chi2_min``, the threshold the
  DAMIT authors use to accept pole and period solutions (e.g. Durech et al. 2016, A&A 587,
  A48; Hanus et al. 2016, A&A 586, A108).
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
        (K,) standard deviations of the log-areas [1] (relative area errors); with relative
        photometry only (no calibrated curve), of the logs of the areas' shares of their sum
        (the scale is not measured).
    residual_scale
        ``s = sqrt(chi2 / (N - p))``.
    residual_dof
        ``N - p`` (``p`` the effective number of parameters, :func:`effective_dof`).
    """

    lambda_deg: float
    beta_deg: float
    period_h: float
    pole_deg: float
    log_area: F64
    residual_scale: float
    residual_dof: float


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


def _shares(cov: F64, areas: F64) -> F64:
    """The covariance with the log-areas ``g_k`` replaced by the logs of the areas' shares
    ``log(a_k / sum a)``: ``d log(a_k / A) = dg_k - sum_j w_j dg_j`` with ``w = a / A`` (the
    delta method), so ``M C M^T`` with ``M = I - 1 w^T`` on the area block. Relative
    photometry does not measure the areas' common scale (only a weak penalty holds it), and
    its variance would otherwise swamp every area's."""
    k = areas.size
    m = np.eye(cov.shape[0])
    m[N_ROTATION:, N_ROTATION:] -= np.outer(np.ones(k), areas / areas.sum())
    return np.asarray(m @ cov @ m.T, dtype=np.float64)


def covariance(model: ConvexModel, sol: ConvexSolution) -> Covariance:
    """Laplace covariance at ``sol`` (module doc)."""
    cov, p_eff = _unscaled_covariance(model, sol)
    dof = max(model.data.n_points - p_eff, 1.0)
    s2 = sol.chi2 / dof
    cov = cov * s2
    if not np.any(model.data.calibrated):
        cov = _shares(cov, sol.areas)
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    lam, bet = np.rad2deg(sd[0]), np.rad2deg(sd[1])
    pole = float(np.hypot(bet, np.cos(sol.theta[1]) * lam))
    return Covariance(
        float(lam),
        float(bet),
        float(sd[2]),
        pole,
        sd[N_ROTATION:],
        float(np.sqrt(s2)),
        float(dof),
    )


def bootstrap(model: ConvexModel, sol: ConvexSolution, draws: int, seed: int) -> tuple[F64, F64]:
    """Bootstrap refits (module doc): (draws, 3) ``(lambda [deg], beta [deg], P [h])`` and
    (draws, K) the facet areas of each refit (the shape's spread, in the units of
    ``sol.areas``)."""
    rng = np.random.default_rng(seed)
    d = model.data
    out = np.empty((draws, 3))
    areas = np.empty((draws, len(model.normals)))
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
        areas[k] = fit.areas
    return out, areas


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


def ambiguity_bound(cov: Covariance) -> float:
    """The chi-square rise within which another pole fits as well as the best:
    ``max(MIRROR_DELTA, sqrt(nu / 2)) s^2`` (module doc)."""
    return max(MIRROR_DELTA, float(np.sqrt(cov.residual_dof / 2.0))) * cov.residual_scale**2


def mirror_ambiguous(best: ConvexSolution, mirror: ConvexSolution, cov: Covariance) -> bool:
    """True when ``mirror`` (or another pole minimum) fits as well as ``best``: its
    chi-square within :func:`ambiguity_bound` of the best's (``cov`` the best's)."""
    return bool(mirror.chi2 - best.chi2 <= ambiguity_bound(cov))


def spans(chi2: F64, scale: float, reference: str = "max") -> bool:
    """True when ``chi2`` rises above its minimum by more than :data:`POLE_DELTA` ``s^2``
    (to its maximum, or to its median with ``reference="median"``)."""
    finite = chi2[np.isfinite(chi2)]
    if finite.size < 2:
        return False
    top = np.max(finite) if reference == "max" else np.median(finite)
    return bool(top - np.min(finite) > POLE_DELTA * scale**2)
