"""Fit of simulated to measured count rates: the per-band scales (plain arrays).

The model of the measured rate ``m[t, j]`` (epoch t, band j) is ``s_j * c[t, j](alpha)``: the
simulated count rate ``c`` of the scenario, for the roughness values ``alpha`` of its rough
materials, times a scale ``s_j`` on the target's reflectance in band j. Intensity is linear
in the reflectance of a Lambertian or microfacet surface (see
:func:`speclight.render.material_contributions`), so for fixed ``alpha`` the scales minimise

.. math::

    \\chi^2 = \\sum_{t, j} w_{tj} (m_{tj} - s_j c_{tj})^2, \\qquad w_{tj} = 1 / \\sigma_{tj}^2,

in closed form (one weighted linear least-squares problem per band):
``s_j = sum_t w m c / sum_t w c^2`` (:func:`fit_scales`); no albedo trial needs a new
simulation. The roughness is fitted in :mod:`speclight.estimate.fitting.roughness_fit`.

Uncertainties: the covariance of the fitted parameters is ``(J^T W J)^-1`` (J the Jacobian
of the model), multiplied by ``max(1, chi^2 / dof)``: when the residuals exceed the
measurement sigmas (sigmas that leave out sky and read noise, or a model that is not exact,
e.g. a rendered target), the spread of the residuals, not the sigmas, measures how well the
data pin the parameters (as ``scipy.optimize.curve_fit`` does with
``absolute_sigma=False``); it is never scaled down.

Missing sigmas: the shot noise of the measured rate,
``sigma = sqrt(max(m, floor) / (t_exp n))`` for ``n`` exposures of ``t_exp`` seconds averaged,
with ``floor`` one detected electron per averaged exposure time (``1 / (t_exp n)``) so that
faint or negative (background-subtracted) rates do not get near-infinite weights.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]


def shot_noise_sigma(rate_per_s: F64, exposure_s: float, n_samples: NDArray | int = 1) -> F64:
    """Shot-noise standard deviation of measured rates [s-1] (module doc: the floor).

    Parameters
    ----------
    rate_per_s
        (N, B) measured rates [s-1].
    exposure_s
        Exposure time of one measurement [s].
    n_samples
        (N,) number of measurements averaged into each rate (1 unless binned).
    """
    r = np.asarray(rate_per_s, dtype=float)
    t = float(exposure_s) * np.asarray(n_samples, dtype=float)
    if r.ndim == 2 and t.ndim == 1:
        t = t[:, None]
    t = np.broadcast_to(t, r.shape)
    electrons = np.maximum(np.where(np.isfinite(r), r, np.nan) * t, 1.0)
    return np.asarray(np.sqrt(electrons) / t, dtype=np.float64)


@dataclass
class ScaleFit:
    """Closed-form weighted least-squares scales, one per band.

    Attributes
    ----------
    scale, scale_std
        (B,) the scales and their standard deviations (NaN where a band is unconstrained).
    chi2
        (B,) weighted sum of squared residuals per band.
    n_used
        (B,) epochs used per band.
    """

    scale: F64
    scale_std: F64
    chi2: F64
    n_used: NDArray[np.int64]


def fit_scales(model: F64, measured: F64, sigma: F64) -> ScaleFit:
    """Per-band scales ``s_j`` minimising ``sum_t (m - s_j c)^2 / sigma^2`` (module doc).

    Entries where any of the three is not finite, or sigma <= 0, are skipped. The standard
    deviation is ``sqrt(1 / sum_t w c^2)`` times ``sqrt(max(1, chi2_j / (n_j - 1)))``.

    Parameters
    ----------
    model, measured, sigma
        (N, B) simulated rates ``c``, measured rates ``m`` and their sigmas [s-1].
    """
    w, c, m = masked_weights(model, measured, sigma)
    wcc = np.sum(w * c * c, axis=0)
    wmc = np.sum(w * m * c, axis=0)
    n_used = np.sum(w > 0, axis=0).astype(np.int64)
    ok = (wcc > 0) & (n_used > 0)
    scale = np.where(ok, wmc / np.where(ok, wcc, 1.0), np.nan)
    chi2 = np.sum(w * (m - np.where(ok, scale, 0.0) * c) ** 2, axis=0)
    dof = np.maximum(n_used - 1, 1)
    inflate = np.maximum(1.0, chi2 / dof)
    std = np.where(ok, np.sqrt(inflate / np.where(ok, wcc, 1.0)), np.nan)
    return ScaleFit(scale, std, chi2, n_used)


def masked_weights(model: F64, measured: F64, sigma: F64) -> tuple[F64, F64, F64]:
    """Weights 1/sigma^2 (0 where any input is not finite or sigma <= 0), and the model and
    measurements with those entries set to 0."""
    c = np.asarray(model, dtype=float)
    m = np.asarray(measured, dtype=float)
    s = np.asarray(sigma, dtype=float)
    good = np.isfinite(c) & np.isfinite(m) & np.isfinite(s) & (s > 0)
    w = np.where(good, 1.0 / np.where(good, s, 1.0) ** 2, 0.0)
    return w, np.where(good, c, 0.0), np.where(good, m, 0.0)


def joint_std(
    cols: list[F64], c: F64, measured: F64, sigma: F64, scale: F64, fit_scale: bool
) -> tuple[F64, F64]:
    """Standard deviations of nonlinear parameters and of the scales, from the joint
    ``(J^T W J)^-1`` (module doc).

    Parameters
    ----------
    cols
        (K,) Jacobian columns d(s_j c_tj)/d p_k of the nonlinear parameters, each (N, B).
    c, measured, sigma
        (N, B) model (unscaled), measurements and sigmas [s-1].
    scale
        (B,) the fitted scales.
    fit_scale
        The scales are fitted too (their columns ``c[:, j]`` join the Jacobian).

    Returns
    -------
    tuple
        (K,) standard deviations of the parameters, (B,) of the scales (0 when not fitted);
        ``inf`` where ``J^T W J`` is singular.
    """
    n_b = c.shape[1]
    s = np.where(np.isfinite(scale), scale, 0.0) if fit_scale else np.ones(n_b)
    w, cc, m = masked_weights(c, measured, sigma)
    sqrt_w = np.sqrt(w).ravel()
    blocks = []
    if fit_scale:
        for j in range(n_b):
            col = np.zeros_like(cc)
            col[:, j] = cc[:, j]
            blocks.append(col.ravel())
    blocks += [np.where(w > 0, np.nan_to_num(d), 0.0).ravel() for d in cols]
    jac = np.stack(blocks, axis=1) * sqrt_w[:, None]
    resid = (m - s[None, :] * cc).ravel() * sqrt_w
    n_used = int(np.count_nonzero(w))
    dof = max(n_used - jac.shape[1], 1)
    inflate = max(1.0, float(resid @ resid) / dof)
    info = jac.T @ jac
    try:
        cov = np.linalg.inv(info) * inflate
        std = np.sqrt(np.where(np.diag(cov) >= 0, np.diag(cov), np.nan))
        if np.linalg.cond(info) > 1e14:
            std = np.full(jac.shape[1], np.inf)
    except np.linalg.LinAlgError:
        std = np.full(jac.shape[1], np.inf)
    k0 = n_b if fit_scale else 0
    std_scale = std[:n_b] if fit_scale else np.zeros(n_b)
    return std[k0:], std_scale


__all__ = ["ScaleFit", "fit_scales", "joint_std", "masked_weights", "shot_noise_sigma"]
