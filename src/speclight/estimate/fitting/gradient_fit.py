"""Roughness fit with analytic derivatives: Gauss-Newton (trust region) in log roughness.

Variable projection (Golub & Pereyra 1973, doi:10.1137/0710036), as
:mod:`speclight.estimate.fitting.roughness_fit`, but with the model's analytic Jacobian
(:class:`speclight.estimate.fitting.roughness_gradient.RoughnessRates`) instead of central
differences, and a least-squares solver instead of SLSQP on chi2: the weighted residuals

    r_tj(alpha) = sqrt(w_tj) (m_tj - s_j(alpha) c_tj(alpha)),
    s_j(alpha) = sum_t w m c / sum_t w c^2          (the closed-form scales),

are minimised over ``x = ln alpha`` by :func:`scipy.optimize.least_squares` (trust region
reflective, bounds ``ln`` of the roughness bounds) with the exact Jacobian of the projected
residuals,

    dr_tj/dalpha_k = -sqrt(w_tj) (s_j dc_tj/dalpha_k + c_tj ds_j/dalpha_k),
    ds_j/dalpha_k = (sum_t w m dc/dalpha_k - 2 s_j sum_t w c dc/dalpha_k) / sum_t w c^2,

times ``alpha_k`` for the log variable. In log roughness a glint's width changes by the same
factor for the same step whatever the roughness, which lets the trust region cover a factor
of 30 in a few steps. Each evaluation is one render pass (rates and Jacobian together);
``least_squares`` asks for the Jacobian at points whose residuals it has, so both come from
one cached pass. With the model's own Poisson noise (:mod:`.noise_model`) the residuals are
the deviance residuals and the Jacobian is that of the Pearson residuals (their Fisher
approximation; the scales' derivative with the expected information).

This is stage 2 of the fit of :mod:`.roughness_fit`: the same scan before it, the same
uncertainties after it (``(J^T W J)^-1`` with the analytic Jacobian).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from speclight.estimate.fitting.fit import F64
from speclight.estimate.fitting.fit_quality import CLIP_SIGMA
from speclight.estimate.fitting.noise_model import Likelihood, PoissonNoise
from speclight.estimate.fitting.roughness_fit import solve
from speclight.estimate.fitting.roughness_problem import RoughnessProblem
from speclight.estimate.fitting.roughness_uncertainty import RoughnessFit

#: least_squares stops when a step changes ln(alpha) by less than this (relative) [1].
XTOL = 1e-6
#: ... or lowers the sum of squares by less than this fraction of it [1].
FTOL = 1e-9
#: Most model evaluations (render passes) of the local method.
MAX_EVALUATIONS = 60


def projected_residuals(
    c: F64, dc: F64, measured: F64, sigma: F64 | PoissonNoise | Likelihood, fit_scale: bool
) -> tuple[F64, F64, F64]:
    """Residuals (N*B,), their Jacobian in alpha (N*B, K) and the scales (B,) (module doc).

    Parameters
    ----------
    c
        Model count rates (N, B) [s-1] at the roughness values ``alpha``.
    dc
        Their derivatives with respect to the K roughness values (N, B, K) [s-1].
    measured
        Measured rates (N, B) [s-1]; NaN: not used.
    sigma
        Their standard deviations (N, B) [s-1], a :class:`.noise_model.PoissonNoise`, or
        the :class:`.noise_model.Likelihood` of ``measured`` (which ``measured`` then is not
        read).
    fit_scale
        Scales in closed form per band (``False``: fixed at 1).
    """
    like = sigma if isinstance(sigma, Likelihood) else Likelihood(measured, sigma)
    use = like.mask(c)
    cc = np.where(use, c, 0.0)
    d = np.where(use[None], np.nan_to_num(dc), 0.0)
    if fit_scale:
        s = like.scales(c)
        s = np.where(np.isfinite(s), s, 0.0)
        ds = like.scale_derivative(c, dc, s)  # (K, B)
    else:
        s, ds = np.ones(c.shape[1]), np.zeros((d.shape[0], c.shape[1]))
    mu = np.where(use, s[None, :] * cc, np.nan)
    r = like.residuals(mu)
    sw = np.sqrt(like.weights(mu))
    jac = -sw[None] * (s[None, None, :] * d + ds[:, None, :] * cc[None])
    return r.ravel(), jac.reshape(d.shape[0], -1).T, s


def fit_roughness_gradient(
    model: Callable[[F64], tuple[F64, F64]],
    measured: F64,
    sigma: F64 | PoissonNoise,
    start: F64,
    bounds: tuple[float, float] = (0.01, 1.0),
    *,
    fit_scale: bool = True,
    on_iteration: Callable[[int, F64, float], None] | None = None,
    max_evaluations: int = MAX_EVALUATIONS,
    scan: bool = True,
    clip_sigma: float | None = CLIP_SIGMA,
) -> RoughnessFit:
    """Fit roughness values (and the band scales) with the model's analytic Jacobian: the
    scan, this trust-region method, the uncertainties (:mod:`.roughness_fit`).

    Parameters
    ----------
    model
        ``model(alpha)`` -> ((N, B) simulated rates [s-1], (K, N, B) their derivatives in
        the K roughness values [s-1]).
    measured
        (N, B) measured rates [s-1].
    sigma
        (N, B) their standard deviations [s-1], or a :class:`.noise_model.PoissonNoise`.
    start
        (K,) initial roughness values (clipped to the bounds).
    bounds
        Lower and upper bound of every roughness.
    fit_scale
        Fit the band scales (else they stay 1).
    on_iteration
        Called with (evaluation, alpha, chi2) after each model evaluation.
    max_evaluations
        Most model evaluations of the local method.
    scan
        Scan the bounds first (:mod:`.roughness_scan`); ``False`` starts the trust region at
        ``start``.
    clip_sigma
        Leave out measurements this many robust sigmas from the fit (:mod:`.fit_quality`);
        None keeps every one.
    """
    problem = RoughnessProblem(model, measured, sigma, bounds, fit_scale=fit_scale,
                               derivatives=True, on_evaluation=on_iteration)  # fmt: skip
    return solve(problem, np.asarray(start, dtype=float), trust_region_refine, scan=scan,
                 max_iterations=max_evaluations, clip_sigma=clip_sigma)  # fmt: skip


def trust_region_refine(
    problem: RoughnessProblem,
    start: F64,
    free: NDArray[np.bool_],
    on_iteration: Callable[[int, F64, float], None] | None,
    max_evaluations: int,
) -> tuple[F64, bool, str, int, None]:
    """``least_squares`` (trust region reflective) over log roughness of the values ``free``
    (module doc)."""
    lo, hi = problem.lo, problem.hi
    idx = np.flatnonzero(free)
    full = np.asarray(start, dtype=float).copy()

    def point(x: F64) -> F64:
        a = full.copy()
        a[idx] = np.clip(np.exp(x), lo, hi)
        return a

    def projected(x: F64) -> tuple[F64, F64, F64]:
        c, dc = problem.evaluate(point(x))
        assert dc is not None
        return projected_residuals(c, dc[idx], c, problem.likelihood, problem.fit_scale)

    def residuals(x: F64) -> F64:
        return projected(x)[0]

    def jacobian(x: F64) -> F64:
        return projected(x)[1] * np.exp(x)[None, :]

    x0 = np.log(full[idx])
    x0 = np.clip(x0, np.log(lo) + 1e-9, np.log(hi) - 1e-9)  # strictly inside for "trf"
    res = least_squares(
        residuals,
        x0,
        jac=jacobian,
        bounds=(np.log(lo), np.log(hi)),
        method="trf",
        x_scale=1.0,
        xtol=XTOL,
        ftol=FTOL,
        max_nfev=max_evaluations,
    )
    return point(np.asarray(res.x, dtype=float)), bool(res.status > 0), str(res.message), \
        int(res.nfev), None  # fmt: skip


__all__ = ["MAX_EVALUATIONS", "fit_roughness_gradient", "projected_residuals",
           "trust_region_refine"]  # fmt: skip
