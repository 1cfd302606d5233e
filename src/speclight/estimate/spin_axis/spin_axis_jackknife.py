"""The refits behind the spin axis's sigmas: the delete-a-block jackknife, its shrinkage
towards isotropic, and the answer on the map at half its resolution.

All refit the misfit of :class:`.spin_axis_gradient.SpinMisfit` from the refined answer's
parameters ``x0`` (the axis's tangent rotation, the phase and, with a free period, the
extra turn) by L-BFGS-B with the analytic gradient; how they are combined is
:mod:`.spin_axis_confidence`'s (module doc there).
"""

from __future__ import annotations

import dataclasses

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.spin_axis.spin_axis_gradient import SpinMisfit
from speclight.estimate.spin_axis.spin_axis_lookup import EpochGeometry

F64 = NDArray[np.float64]
#: Blocks of consecutive epochs of the jackknife.
JACKKNIFE_BLOCKS = 10


def refit(model: SpinMisfit, x0: F64) -> F64:
    """The parameters (K,) minimising ``model``'s misfit from ``x0`` (L-BFGS-B, analytic
    gradient)."""
    from scipy.optimize import minimize

    res = minimize(
        model.misfit_and_gradient, x0, jac=True, method="L-BFGS-B",
        options={"maxiter": 100, "ftol": 1e-12, "gtol": 1e-9},
    )  # fmt: skip
    return np.asarray(res.x, dtype=float)


def jackknife_refits(model: SpinMisfit, x0: F64, ranged: bool) -> F64:
    """The refits (G, K) of the delete-a-block jackknife: the pass cut into
    :data:`JACKKNIFE_BLOCKS` runs of consecutive epochs, the fit repeated without each."""
    n_t = model.y.shape[0]
    edges = np.linspace(0, n_t, JACKKNIFE_BLOCKS + 1).astype(int)
    xs = []
    for g in range(JACKKNIFE_BLOCKS):
        keep = np.ones(n_t, dtype=bool)
        keep[edges[g] : edges[g + 1]] = False
        geo = model.geo
        sub = dataclasses.replace(
            model,
            geo=EpochGeometry(
                geo.sun_gcrs[keep], geo.observer_gcrs[keep], geo.t_s[keep], geo.period_s
            ),
            y=model.y[keep],
            ranging=model.ranging.select(keep)
            if ranged and model.ranging is not None
            else model.ranging,
        )
        xs.append(refit(sub, x0))
    return np.array(xs)


def jackknife_spread(xs: F64) -> F64:
    """``(G - 1) / G sum_g (x_g - mean x)(x_g - mean x)^T`` (K, K) of refits ``xs`` (G, K)."""
    d = xs - xs.mean(axis=0)
    return np.asarray((xs.shape[0] - 1) / xs.shape[0] * (d.T @ d))


def shrunk_jackknife_spread(xs: F64) -> tuple[F64, float]:
    """:func:`jackknife_spread` of refits ``xs`` (G, K) with its axis block shrunk towards
    the isotropic (:func:`shrunk_second_moment` of the deviations from the refits' mean,
    times ``G - 1``). Returns the covariance (K, K) and the intensity ``lambda``."""
    g = xs.shape[0]
    s, lam = shrunk_second_moment(xs - xs.mean(axis=0))
    return (g - 1) * s, lam


def shrunk_second_moment(d: F64) -> tuple[F64, float]:
    """``S = 1 / G sum_g d_g d_g^T`` (K, K) of deviations ``d`` (G, K) with its axis block
    shrunk towards the isotropic ``mu I`` (``mu`` half its trace) by Ledoit & Wolf's (2004,
    J. Multivar. Anal. 88, 365, doi:10.1016/S0047-259X(03)00096-4, Lemma 3.2 / Theorem 3.2)
    intensity ``lambda = min(beta^2, delta^2) / delta^2`` estimated from the deviations
    themselves: ``delta^2 = ||S_aa - mu I||^2`` (the block's anisotropy), ``beta^2 = 1 / G^2
    sum_g ||d_g d_g^T - S_aa||^2`` (how much of it G deviations can resolve), ``S_aa`` the
    axis block of ``S``. Returns ``lambda T + (1 - lambda) S`` and ``lambda`` (1: only the
    axis block's size is kept); ``T`` is the block ``mu I`` beside ``S``'s own other block
    (phase, period): only the axis block is shrunk and the cross terms go with ``1 - lambda``;
    ``T`` and ``S`` are positive semi-definite, so is the sum."""
    g = d.shape[0]
    s = d.T @ d / g
    block = s[:2, :2]
    mu = float(np.trace(block)) / 2.0
    delta2 = float(np.sum((block - mu * np.eye(2)) ** 2))
    beta2 = float(np.mean([np.sum((np.outer(v, v) - block) ** 2) for v in d[:, :2]])) / g
    lam = min(beta2, delta2) / delta2 if delta2 > 0 else 1.0
    target = np.zeros_like(s)
    target[:2, :2] = mu * np.eye(2)
    target[2:, 2:] = s[2:, 2:]
    return np.asarray(lam * target + (1 - lam) * s), lam


def jackknife_covariance(model: SpinMisfit, x0: F64, ranged: bool) -> F64:
    """Delete-a-block jackknife covariance (K, K) of the parameters ``x`` (Efron & Stein
    1981; Kuensch 1989, Ann. Stat. 17, 1217, doi:10.1214/aos/1176347265): the pass is cut
    into :data:`JACKKNIFE_BLOCKS` runs of consecutive epochs, the fit is repeated without
    each (:func:`jackknife_refits`, from ``x0``), and :func:`jackknife_spread` of the refits.
    It sees what the residuals do to the answer: noise and a map error that varies along
    the pass alike."""
    return jackknife_spread(jackknife_refits(model, x0, ranged))


def half_resolution(model: SpinMisfit) -> SpinMisfit | None:
    """``model`` on its map coarsened to half its ``nside``
    (:func:`.spin_axis_continuation.coarsen_map`), or None for ``nside`` 1 (none coarser);
    the ranging term (its own map) is kept as it is."""
    from speclight.estimate.spin_axis.spin_axis_continuation import coarsen_map

    nside = model.bmap.header.nside
    if nside < 2:
        return None
    return dataclasses.replace(model, bmap=coarsen_map(model.bmap, nside // 2, None))


def map_error_covariance(model: SpinMisfit, x0: F64) -> F64:
    """An isotropic variance (K, K) on the axis block for the map's own error, measured by
    halving the map's resolution.

    The map's HEALPix interpolation errs by ``k h^2`` (bilinear, ``h`` the pixel size), so
    the answer refitted (:func:`refit`, from ``x0``) on the map coarsened to half its
    ``nside`` (:func:`half_resolution`: ``2 h``, ``4 k h^2``) moves by about 3 times what
    the map's error does to it: ``sigma_map = |shift| / 3`` on each axis component (the
    shift's direction is that of the coarse map's error, not the map's: only its size is
    used). Zero for a map of ``nside`` 1.
    """
    k = x0.size
    coarse = half_resolution(model)
    if coarse is None:
        return np.zeros((k, k))
    shift = refit(coarse, x0)[:2] - x0[:2]
    if not np.all(np.isfinite(shift)):
        return np.zeros((k, k))
    out = np.zeros((k, k))
    out[0, 0] = out[1, 1] = float(np.sum(shift**2)) / 9.0
    return out
