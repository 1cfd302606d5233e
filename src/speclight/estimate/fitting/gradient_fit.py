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
one cached pass. Uncertainties: ``(J^T W J)^-1`` with the analytic Jacobian
(:func:`speclight.estimate.fitting.fit.joint_std`), and the same chi2 profile check as the
SLSQP fit.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.optimize import least_squares

from speclight.estimate.fitting.fit import F64, ScaleFit, fit_scales, joint_std, masked_weights
from speclight.estimate.fitting.roughness_fit import RoughnessFit, chi2_profile

#: least_squares stops when a step changes ln(alpha) by less than this (relative) [1].
XTOL = 1e-6
#: ... or lowers the sum of squares by less than this fraction of it [1].
FTOL = 1e-9
#: Most model evaluations (render passes) of one fit.
MAX_EVALUATIONS = 60


def projected_residuals(
    c: F64, dc: F64, measured: F64, sigma: F64, fit_scale: bool
) -> tuple[F64, F64, F64]:
    """Residuals (N*B,), their Jacobian in alpha (N*B, K) and the scales (B,) (module doc).

    Parameters
    ----------
    c
        Model count rates (N, B) [s-1] at the roughness values ``alpha``.
    dc
        Their derivatives with respect to the K roughness values (N, B, K) [s-1].
    measured, sigma
        Measured rates and their standard deviations (N, B) [s-1]; NaN: not used.
    fit_scale
        Scales in closed form per band (``False``: fixed at 1).
    """
    w, cc, m = masked_weights(c, measured, sigma)
    d = np.where(w[None] > 0, np.nan_to_num(dc), 0.0)
    sw = np.sqrt(w)
    if fit_scale:
        wcc = np.sum(w * cc * cc, axis=0)
        ok = wcc > 0
        den = np.where(ok, wcc, 1.0)
        s = np.where(ok, np.sum(w * m * cc, axis=0) / den, 0.0)
        ds = np.where(
            ok,
            (np.sum(w * m * d, axis=1) - 2 * s * np.sum(w * cc * d, axis=1)) / den,
            0.0,
        )  # (K, B)
    else:
        s, ds = np.ones(c.shape[1]), np.zeros((d.shape[0], c.shape[1]))
    r = sw * (m - s * cc)
    jac = -sw[None] * (s[None, None, :] * d + ds[:, None, :] * cc[None])
    return r.ravel(), jac.reshape(d.shape[0], -1).T, s


def fit_roughness_gradient(
    model: Callable[[F64], tuple[F64, F64]],
    measured: F64,
    sigma: F64,
    start: F64,
    bounds: tuple[float, float] = (0.01, 1.0),
    *,
    fit_scale: bool = True,
    on_iteration: Callable[[int, F64, float], None] | None = None,
    max_evaluations: int = MAX_EVALUATIONS,
) -> RoughnessFit:
    """Fit roughness values (and the band scales) with the model's analytic Jacobian.

    Parameters
    ----------
    model
        ``model(alpha)`` -> ((N, B) simulated rates [s-1], (K, N, B) their derivatives in
        the K roughness values [s-1]).
    measured, sigma
        (N, B) measured rates and their sigmas [s-1].
    start
        (K,) initial roughness values (clipped to the bounds).
    bounds
        Lower and upper bound of every roughness.
    fit_scale
        Fit the band scales (else they stay 1).
    on_iteration
        Called with (evaluation, alpha, chi2) after each model evaluation.
    max_evaluations
        Most model evaluations of the solver (the final std and profile add 1 + 2K at most).
    """
    lo, hi = float(bounds[0]), float(bounds[1])
    cache: dict[tuple[float, ...], tuple[F64, F64]] = {}

    def evaluate(alpha: F64) -> tuple[F64, F64]:
        key = tuple(float(a) for a in np.round(alpha, 12))
        if key not in cache:
            c, dc = model(np.array(key))
            cache[key] = (np.asarray(c, float), np.asarray(dc, float))
            if on_iteration is not None:
                r, _, _ = projected_residuals(*cache[key], measured, sigma, fit_scale)
                on_iteration(len(cache), np.array(key), float(r @ r))
        return cache[key]

    def residuals(x: F64) -> F64:
        return projected_residuals(*evaluate(np.exp(x)), measured, sigma, fit_scale)[0]

    def jacobian(x: F64) -> F64:
        alpha = np.exp(x)
        return projected_residuals(*evaluate(alpha), measured, sigma, fit_scale)[1] * alpha[None, :]

    x0 = np.log(np.clip(np.asarray(start, dtype=float), lo, hi))
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
    alpha = np.clip(np.exp(np.asarray(res.x, dtype=float)), lo, hi)
    c, dc = evaluate(alpha)
    scales = fit_scales(c, measured, sigma)
    w, cc, m = masked_weights(c, measured, sigma)
    n_data = int(np.count_nonzero(w))
    if not fit_scale:
        chi2_fixed = np.sum(w * (m - cc) ** 2, axis=0)
        scales = ScaleFit(np.ones(c.shape[1]), np.zeros(c.shape[1]), chi2_fixed, scales.n_used)
    s = np.where(np.isfinite(scales.scale), scales.scale, 0.0)
    cols = [np.where(w > 0, np.nan_to_num(dc[k]), 0.0) * s[None, :] for k in range(alpha.size)]
    std_alpha, std_scale = joint_std(cols, c, measured, sigma, scales.scale, fit_scale)

    def chi2(a: F64) -> float:
        r = projected_residuals(*evaluate(np.clip(a, lo, hi)), measured, sigma, fit_scale)[0]
        return float(r @ r)

    if fit_scale and np.all(np.isfinite(std_alpha) & (std_alpha <= hi - lo)):
        scales.scale_std = std_scale
    elif fit_scale:  # a roughness the data do not pin: the joint std says nothing useful
        scales.scale_std = _spread_std(scales, cache, chi2, measured, sigma, n_data)
    top = np.nanmax(np.abs(c)) if np.any(np.isfinite(c)) else 0.0
    derivative = np.array(
        [float(np.nanmax(np.abs(dc[k])) / top) if top > 0 else 0.0 for k in range(alpha.size)]
    )

    profile = chi2_profile(chi2, alpha, std_alpha, (lo, hi), n_data, fit_scale, scales.chi2)
    return RoughnessFit(
        roughness=alpha,
        roughness_std=std_alpha,
        scales=scales,
        model=c,
        success=bool(res.status > 0),
        message=str(res.message),
        n_iterations=int(res.nfev),
        n_simulations=len(cache),
        derivative=derivative,
        profile=profile,
    )


def _spread_std(
    scales: ScaleFit,
    cache: dict[tuple[float, ...], tuple[F64, F64]],
    chi2: Callable[[F64], float],
    measured: F64,
    sigma: F64,
    n_data: int,
) -> F64:
    """The scales' std at the fitted roughness, widened to half the spread of the scales over
    the evaluated roughness values whose chi2 is within one reduced chi2 of the best (those
    the data cannot tell apart), as the SLSQP fit does over its scan."""
    values = {key: chi2(np.array(key)) for key in cache}
    best = min(values.values())
    n_par = len(next(iter(cache))) + scales.scale.size
    unit = max(1.0, best / max(n_data - n_par, 1))
    alike = [fit_scales(cache[k][0], measured, sigma).scale for k, v in values.items()
             if v - best < unit]  # fmt: skip
    found = np.array(alike)
    spread = (found.max(axis=0) - found.min(axis=0)) / 2
    return np.asarray(np.maximum(scales.scale_std, spread), dtype=float)


__all__ = ["MAX_EVALUATIONS", "fit_roughness_gradient", "projected_residuals"]
