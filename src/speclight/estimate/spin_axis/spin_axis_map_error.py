"""The spin axis's covariance from the map's own error: a random field over the map's nodes,
its size from the residuals' part common to the bands, its effect on the answer by refits.

**The field.** The search map holds its band rates on nodes (HEALPix directions x phase
angles x rolls) and interpolates between them; its own error (how far the interpolant is
from the target's true intensity) is modelled as a relative error ``tau eps_n`` per node,
``eps_n ~ N(0, 1)`` independent between nodes and common to the bands, interpolated as the
map is: the map's rates become ``M_nb (1 + tau eps_n)``. Two epochs whose geometries fall
between the same nodes share their errors (correlation length: one node spacing in
direction, phase angle and roll), which neither the residuals' spread along the pass (the
jackknife over time blocks) nor their autocorrelation (the sandwich) sees.

**Its size** ``tau^2`` is what the residuals hold in common across the bands
(:func:`cross_band_power`: noise independent between bands cancels there, so no noise
floor is needed; on the calibration bench the residuals above the noise are nearly all
common to the 32 bands, and this statistic of the refined residuals matches, within ~20 %,
that of the search map's true error). The field is matched on the same statistic: ``tau^2
= P(r) / E P((I - H) dr)`` with ``r`` the refined residuals, ``dr`` the residuals' first-order
change under one unit draw of the field (:func:`residual_perturbations`: ``dp_tb = p_tb
eps(t)`` through the normalisation by each band's mean), ``H = J A^-1 J^T`` the part the
parameters absorb (``A = J^T J``) and ``E`` the mean over :data:`N_LINEAR` draws.

**Its effect** (:func:`map_field_covariance`): the answer refitted
(:func:`.spin_axis_jackknife.refit`, from the refined answer ``x0``) on :data:`N_REFITS`
maps perturbed by draws of the field, the covariance ``1 / N sum (x_i - x0)(x_i - x0)^T``
(a parametric bootstrap: the field has zero mean). The refits, not the first-order
``A^-1 J^T Cov(dr) J A^-1`` (:func:`propagated_covariance`): on the calibration bench the
search map's true error moves the answer by several times what that first-order step
predicts (the misfit surface is not quadratic on the scale of the map's cells), and the
refits see that. Draws from a fixed seed, so the answer is repeatable.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.spin_axis.spin_axis_gradient import SpinMisfit
from speclight.estimate.spin_axis.spin_axis_jackknife import refit

F64 = NDArray[np.float64]
#: First-order draws of the field that fix its size.
N_LINEAR = 256
#: Refits on perturbed maps (the bootstrap).
N_REFITS = 10
#: Seed of the field's draws (the covariance is the same on every run).
SEED = 20261204


def cross_band_power(r: F64, n_t: int, n_b: int) -> F64:
    """``sum_t sum_{b != b'} r_tb r_tb' / (B - 1)`` of residuals (..., M) whose first ``T B``
    are epoch-major (T, B): of ``r_tb = c_t + n_tb`` with ``n_tb`` independent between the
    bands and of zero mean, it is ``sum_t B c_t^2`` in expectation (module doc); NaN for one
    band."""
    if n_b < 2:
        return np.full(r.shape[:-1], np.nan)
    e = r[..., : n_t * n_b].reshape(*r.shape[:-1], n_t, n_b)
    both = np.sum(np.sum(e, axis=-1) ** 2, axis=-1) - np.sum(e**2, axis=(-1, -2))
    return np.asarray(both / (n_b - 1))


def residual_perturbations(model: SpinMisfit, x0: F64, eps: F64) -> F64:
    """First-order changes ``dr`` (N, M) of ``model``'s residuals at ``x0`` under relative
    rate errors ``eps`` (T, N) common to the bands (module doc; the ranging residuals, where
    there are any, unchanged: zeros)."""
    sun, obs = model.body_directions(x0)
    p = model.bmap.intensity_1au(sun, obs)  # (T, B)
    n_t, n_b = p.shape
    m = np.mean(p, axis=0)
    dp = p[None] * eps.T[:, :, None]  # (N, T, B)
    dm = np.mean(dp, axis=1)  # (N, B)
    dr = ((dp / m - p[None] * (dm / m**2)[:, None, :]) / np.sqrt(n_t * n_b)).reshape(
        eps.shape[1], n_t * n_b
    )
    n_extra = 0 if model.ranging is None else model.ranging.offset_m.size
    return np.concatenate([dr, np.zeros((dr.shape[0], n_extra))], axis=1)


def propagated_covariance(jac: F64, dr: F64) -> tuple[F64, F64]:
    """First order of perturbations ``dr`` (N, M) of the residuals of Jacobian ``jac``
    (M, K): the parameters' covariance ``A^-1 J^T Cov(dr) J A^-1`` (K, K) (``Cov(dr)`` the
    draws' mean ``dr dr^T``: zero-mean draws) and the residuals the fit leaves,
    ``(I - J A^-1 J^T) dr`` (N, M)."""
    a_inv = np.linalg.pinv(jac.T @ jac)
    dx = -(dr @ jac) @ a_inv  # (N, K): -A^-1 J^T dr per draw (A^-1 symmetric)
    return np.asarray(dx.T @ dx / dr.shape[0]), dr + dx @ jac.T


def field_draws(model: SpinMisfit, n_draws: int, rng: np.random.Generator) -> F64:
    """``n_draws`` unit draws of the field at the map's nodes (D, P, R, N) (float32)."""
    shape = (*model.bmap.intensity_W_sr_nm.shape[:-1], n_draws)
    return rng.standard_normal(shape, dtype=np.float32)


def field_variance(model: SpinMisfit, x0: F64, r: F64, jac: F64, rng: np.random.Generator) -> float:
    """``tau^2`` (module doc) of the refined residuals ``r`` (M,) and their Jacobian ``jac``
    (M, K); 0 where the residuals hold nothing common to the bands, NaN for one band."""
    n_t, n_b = model.y.shape
    unit = dataclasses.replace(model.bmap, intensity_W_sr_nm=field_draws(model, N_LINEAR, rng))
    eps = unit.intensity_1au(*model.body_directions(x0))  # (T, N)
    left = propagated_covariance(jac, residual_perturbations(model, x0, eps))[1]
    seen = float(cross_band_power(r, n_t, n_b))
    per_unit = float(np.mean(cross_band_power(left, n_t, n_b)))
    if not (np.isfinite(seen) and np.isfinite(per_unit) and per_unit > 0):
        return float("nan")
    return max(seen, 0.0) / per_unit


def map_field_covariance(model: SpinMisfit, x0: F64, n_refits: int = N_REFITS) -> F64:
    """The parameters' covariance (K, K) from the map's error field (module doc) around the
    refined answer ``x0``; zeros where the model has no finite residuals or gradient there,
    or the field's size is not defined (one band)."""
    k = x0.size
    r, jac = model.residuals(x0)
    if jac is None or not np.all(np.isfinite(r)) or not np.any(jac):
        return np.zeros((k, k))
    rng = np.random.default_rng(SEED)
    tau2 = field_variance(model, x0, r, jac, rng)
    if not (np.isfinite(tau2) and tau2 > 0):
        return np.zeros((k, k))
    values = model.bmap.intensity_W_sr_nm
    dev = []
    for eps in np.moveaxis(field_draws(model, n_refits, rng), -1, 0):
        scaled = values * (1.0 + np.float32(np.sqrt(tau2)) * eps)[..., None]
        bumped = dataclasses.replace(model.bmap, intensity_W_sr_nm=scaled)
        dev.append(refit(dataclasses.replace(model, bmap=bumped), x0) - x0)
    d = np.array(dev)
    if not np.all(np.isfinite(d)):
        return np.zeros((k, k))
    return np.asarray(d.T @ d / n_refits)
