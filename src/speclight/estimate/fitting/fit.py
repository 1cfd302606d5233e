"""Fit of simulated to measured count rates: the per-band scales (plain arrays).

The model of the measured rate ``m[t, j]`` (epoch t, band j) is ``s_j * c[t, j](alpha)``: the
simulated count rate ``c`` of the scenario, for the roughness values ``alpha`` of its rough
materials, times a scale ``s_j`` on the target's reflectance in band j. Intensity is linear
in the reflectance of a Lambertian or microfacet surface (see
:func:`speclight.render.material_contributions`), so for fixed ``alpha`` the scales are one
problem per band and no albedo trial needs a new simulation (:func:`fit_scales`): with the
measurements' own sigmas the minimum of

.. math::

    \\chi^2 = \\sum_{t, j} w_{tj} (m_{tj} - s_j c_{tj})^2, \\qquad w_{tj} = 1 / \\sigma_{tj}^2,

``s_j = sum_t w m c / sum_t w c^2``; without them, the minimum of the Poisson deviance of the
model's own shot noise (:mod:`speclight.estimate.fitting.noise_model`, which says why not
the measured rate's). The roughness is fitted in
:mod:`speclight.estimate.fitting.roughness_fit`.

Uncertainties: the covariance of the fitted parameters is ``(J^T W J)^-1`` (J the Jacobian
of the model, W the Fisher weights ``1 / var(m)`` at the fitted model), multiplied by
``max(1, chi^2 / dof)``: when the residuals exceed the noise model (sigmas that leave out
sky and read noise, or a model that is not exact, e.g. a rendered target), the spread of
the residuals, not the noise model, measures how well the data pin the parameters (as
``scipy.optimize.curve_fit`` does with ``absolute_sigma=False``); it is never scaled down.

:func:`shot_noise_sigma` is the shot noise of a measured rate itself (Neyman's sigma), for
users who want sigmas from the data; the fit does not use it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.fitting.noise_model import Likelihood, PoissonNoise

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
    """Closed-form scales, one per band.

    Attributes
    ----------
    scale, scale_std
        (B,) the scales and their standard deviations (NaN where a band is unconstrained).
    chi2
        (B,) chi-square (Poisson: deviance) per band.
    n_used
        (B,) epochs used per band.
    """

    scale: F64
    scale_std: F64
    chi2: F64
    n_used: NDArray[np.int64]


def fit_scales(model: F64, measured: F64, sigma: F64 | PoissonNoise) -> ScaleFit:
    """Per-band scales ``s_j`` of the model ``s_j c`` that best match the measured rates.

    With sigmas, the minimum of ``sum_t (m - s_j c)^2 / sigma^2``; with a
    :class:`~speclight.estimate.fitting.noise_model.PoissonNoise`, of the Poisson deviance
    (:mod:`.noise_model`). Entries where the model or the measurement is not finite, or
    sigma <= 0, are skipped. The standard deviation is ``sqrt(1 / sum_t w c^2)`` (``w`` the
    Fisher weight ``1 / var(m)`` at the fitted model) times ``sqrt(max(1, chi2_j / (n_j -
    1)))``.

    Parameters
    ----------
    model, measured
        (N, B) simulated rates ``c`` and measured rates ``m`` [s-1].
    sigma
        (N, B) the measured rates' standard deviations [s-1], or a ``PoissonNoise``.
    """
    return scale_fit(Likelihood(measured, sigma), model)


def scale_fit(likelihood: Likelihood, model: F64) -> ScaleFit:
    """:func:`fit_scales` of a :class:`~.noise_model.Likelihood`: scales, their standard
    deviations (Fisher weights at the fitted model, inflated by ``max(1, chi2 / dof)`` per
    band) and the deviance per band."""
    c = np.asarray(model, dtype=float)
    use = likelihood.mask(c)
    scale = likelihood.scales(c)
    fitted = np.where(np.isfinite(scale), scale, 0.0)[None, :] * np.where(use, c, 0.0)
    chi2 = likelihood.deviance(np.where(use, fitted, np.nan))
    w = likelihood.weights(np.where(use, fitted, np.nan))
    wcc = np.sum(w * np.where(use, c, 0.0) ** 2, axis=0)
    n_used = np.sum(use, axis=0).astype(np.int64)
    ok = np.isfinite(scale) & (wcc > 0)
    inflate = np.maximum(1.0, chi2 / np.maximum(n_used - 1, 1))
    std = np.where(ok, np.sqrt(inflate / np.where(ok, wcc, 1.0)), np.nan)
    return ScaleFit(np.where(ok, scale, np.nan), std, chi2, n_used)


def joint_std(
    cols: list[F64], c: F64, likelihood: Likelihood, scale: F64, fit_scale: bool
) -> tuple[F64, F64]:
    """Standard deviations of nonlinear parameters and of the scales, from the joint
    ``(J^T W J)^-1`` (module doc).

    A parameter the data cannot see (a zero column, or one in the null space of ``J^T W
    J``) gets ``inf`` and is left out of the others' covariance, so that one unconstrained
    roughness does not make every other one unconstrained too.

    Parameters
    ----------
    cols
        (K,) Jacobian columns d(s_j c_tj)/d p_k of the nonlinear parameters, each (N, B).
    c
        (N, B) model (unscaled) [s-1].
    likelihood
        The measured rates and their noise (:class:`.noise_model.Likelihood`).
    scale
        (B,) the fitted scales.
    fit_scale
        The scales are fitted too (their columns ``c[:, j]`` join the Jacobian).

    Returns
    -------
    tuple
        (K,) standard deviations of the parameters, (B,) of the scales (0 when not fitted).
    """
    n_b = c.shape[1]
    s = np.where(np.isfinite(scale), scale, 0.0) if fit_scale else np.ones(n_b)
    use = likelihood.mask(c)
    cc = np.where(use, c, 0.0)
    w = likelihood.weights(s[None, :] * cc)
    sqrt_w = np.sqrt(w).ravel()
    blocks = []
    if fit_scale:
        for j in range(n_b):
            col = np.zeros_like(cc)
            col[:, j] = cc[:, j]
            blocks.append(col.ravel())
    blocks += [np.where(use, np.nan_to_num(d), 0.0).ravel() for d in cols]
    jac = np.stack(blocks, axis=1) * sqrt_w[:, None]
    resid = likelihood.residuals(s[None, :] * cc).ravel()
    n_used = int(np.count_nonzero(use))
    dof = max(n_used - jac.shape[1], 1)
    inflate = max(1.0, float(resid @ resid) / dof)
    std = np.sqrt(inflate) * _std_of_identifiable(jac.T @ jac)
    k0 = n_b if fit_scale else 0
    std_scale = std[:n_b] if fit_scale else np.zeros(n_b)
    return std[k0:], std_scale


#: An information matrix whose condition number exceeds this is singular in float64.
MAX_CONDITION = 1e14


def _std_of_identifiable(info: F64) -> F64:
    """sqrt(diag(info^-1)) over the parameters that can be identified; ``inf`` for those
    left out, one at a time, while ``info`` is singular (the parameter with the largest
    share of the null direction first)."""
    k = info.shape[0]
    keep = np.ones(k, dtype=bool)
    std = np.full(k, np.inf)
    scale = np.sqrt(np.where(np.diag(info) > 0, np.diag(info), 1.0))
    keep &= np.diag(info) > 0
    while keep.any():
        idx = np.flatnonzero(keep)
        sub = info[np.ix_(idx, idx)] / np.outer(scale[idx], scale[idx])  # unit diagonal
        values, vectors = np.linalg.eigh(sub)
        if values[0] > values[-1] / MAX_CONDITION:
            cov = (vectors / values) @ vectors.T
            diag = np.diag(cov) / scale[idx] ** 2
            std[idx] = np.sqrt(np.where(diag >= 0, diag, np.inf))
            break
        keep[idx[int(np.argmax(np.abs(vectors[:, 0])))]] = False
    return std


__all__ = ["ScaleFit", "fit_scales", "joint_std", "scale_fit", "shot_noise_sigma"]
