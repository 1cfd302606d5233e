"""The spin axis's covariance from the map's own error: a random displacement of the map's
directions, its size from the residuals' part common to the bands, its effect on the answer
by refits.

**The field.** The search map holds its band rates on HEALPix directions (x phase angles x
rolls) and interpolates between them; where the target's intensity has sharp features (a
panel's glint) the interpolant puts them a fraction of a pixel off. The map's error is
modelled as such a misplacement: each direction node ``d_n`` displaced by a tangent vector
``s u_n`` (``u_n`` two independent ``N(0, 1)`` components along the node's east and north,
independent between the nodes: correlation length one node spacing; common to the phase
angles, rolls and bands), the map resampled there with its own interpolation
(:func:`warped_map`). An additive error per node was tried first: it left the bench's
largest errors (the answer pulled along the direction a glint's position pins) at 5-25
sigma; BENCHMARKS.md "Spin-axis calibration: the map's error as a field".

**Its size** ``s`` is matched on what the residuals hold in common across the bands
(:func:`cross_band_power`: noise independent between the bands cancels there, so no noise
floor is needed; on the calibration bench the residuals above the noise are nearly all
common to the 32 bands, and this statistic of the refined residuals matches that of the
search map's true error within ~20 % in 19 of 23 draws, not where the parameters absorb
it): each draw displaced by :data:`PROBE_PIXELS` of a pixel (only the directions the
epochs read at the answer: :func:`track_nodes`) changes the refined residuals by ``dr``,
the fit leaves ``(I - J A^-1 J^T) dr`` (:func:`propagated_covariance`) whose common power
grows as ``s^2`` for small ``s``, so ``s^2 = s_probe^2 P(r) / mean P((I - H) dr)``.

**Its effect** (:func:`map_warp_deviations`): the answer refitted
(:func:`.spin_axis_jackknife.refit`, from the refined answer ``x0``) on the map displaced
by each of :data:`N_DRAWS` draws at that size; the covariance is their second moment about
``x0`` (the field has zero mean) with its axis block shrunk towards isotropic as far as the
draws leave its shape unresolved (:func:`map_warp_covariance`). Refits, not the first-order
``A^-1 J^T Cov(dr) J A^-1``: on the bench the search map's true error moves the answer by
several times what that first-order step predicts (the misfit surface is not quadratic on
the scale of the map's pixels). Draws from a fixed seed, so the answer is repeatable.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.spin_axis.spin_axis_gradient import SpinMisfit
from speclight.estimate.spin_axis.spin_axis_jackknife import refit, shrunk_second_moment
from speclight.maps.map_geometry import map_coordinates, sun_observer
from speclight.maps.map_lookup import ReflectivityMap, healpix_weights

F64 = NDArray[np.float64]
#: Draws of the displacement (each: one probe and one refit).
N_DRAWS = 10
#: The probe's displacement [pixels]: small, so the residuals' change is linear in it.
PROBE_PIXELS = 0.05
#: Seed of the draws (the covariance is the same on every run).
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


def propagated_covariance(jac: F64, dr: F64) -> tuple[F64, F64]:
    """First order of perturbations ``dr`` (N, M) of the residuals of Jacobian ``jac``
    (M, K): the parameters' covariance ``A^-1 J^T Cov(dr) J A^-1`` (K, K) (``Cov(dr)`` the
    draws' mean ``dr dr^T``: zero-mean draws) and the residuals the fit leaves,
    ``(I - J A^-1 J^T) dr`` (N, M)."""
    a_inv = np.linalg.pinv(jac.T @ jac)
    dx = -(dr @ jac) @ a_inv  # (N, K): -A^-1 J^T dr per draw (A^-1 symmetric)
    return np.asarray(dx.T @ dx / dr.shape[0]), dr + dx @ jac.T


def warped_map(
    bmap: ReflectivityMap, shift_rad: F64, nodes: NDArray[np.int64] | None = None
) -> ReflectivityMap:
    """``bmap`` resampled (its own interpolation) at its directions displaced by the tangent
    vectors ``shift_rad`` (D, 2) [rad] (east, north of each direction; the roll measured at
    the displaced direction), on its own nodes; only the directions ``nodes`` (all: None),
    the others kept as they are."""
    nodes = np.arange(bmap.direction_body.shape[0]) if nodes is None else nodes
    d = bmap.direction_body[nodes]
    e_lon, e_lat = bmap.roll_frames[0][nodes], bmap.roll_frames[1][nodes]
    p = d + shift_rad[nodes, :1] * e_lon + shift_rad[nodes, 1:] * e_lat
    p /= np.linalg.norm(p, axis=1)[:, None]
    angles = np.radians(bmap.header.phase_angle_deg)
    rolls = 2 * np.pi * np.arange(bmap.header.roll_deg.size) / bmap.header.roll_deg.size
    n_d, n_p, n_r = d.shape[0], angles.size, rolls.size
    sun, obs = sun_observer(
        np.repeat(p, n_p * n_r, axis=0), np.tile(np.repeat(angles, n_r), n_d),
        np.tile(rolls, n_d * n_p),
    )  # fmt: skip
    values = np.array(bmap.intensity_W_sr_nm)
    values[nodes] = bmap.intensity_1au(sun, obs).reshape(n_d, n_p, n_r, -1)
    return dataclasses.replace(bmap, intensity_W_sr_nm=values)


def pixel_rad(bmap: ReflectivityMap) -> float:
    """The map's pixel size ``sqrt(4 pi / D)`` [rad]."""
    return float(np.sqrt(4 * np.pi / bmap.direction_body.shape[0]))


def track_nodes(model: SpinMisfit, x0: F64) -> NDArray[np.int64]:
    """The map's directions (indices) the epochs' lookups at ``x0`` read (the 4 HEALPix
    neighbours of each epoch's phase vector): the only ones a change of the residuals at
    ``x0`` depends on."""
    sun, obs = model.body_directions(x0)
    phase_vectors = map_coordinates(sun, obs)[0]
    pix = healpix_weights(model.bmap.header.nside, phase_vectors)[1]
    return np.unique(pix)


def warp_scale(model: SpinMisfit, x0: F64, r: F64, jac: F64, unit: F64) -> float:
    """The displacement's size ``s`` [rad] (module doc) of the refined residuals ``r`` (M,),
    their Jacobian ``jac`` (M, K) and unit draws ``unit`` (N, D, 2); NaN for one band or
    where the probes change nothing common to the bands."""
    n_t, n_b = model.y.shape
    probe = PROBE_PIXELS * pixel_rad(model.bmap)
    nodes = track_nodes(model, x0)
    dr = []
    for u in unit:
        moved = dataclasses.replace(model, bmap=warped_map(model.bmap, probe * u, nodes))
        dr.append(moved.residuals(x0, jacobian=False)[0] - r)
    left = propagated_covariance(jac, np.array(dr))[1]
    seen = float(cross_band_power(r, n_t, n_b))
    per_probe = float(np.mean(cross_band_power(left, n_t, n_b)))
    if not (np.isfinite(seen) and np.isfinite(per_probe) and per_probe > 0):
        return float("nan")
    return probe * float(np.sqrt(max(seen, 0.0) / per_probe))


def map_warp_deviations(model: SpinMisfit, x0: F64, n_draws: int = N_DRAWS) -> F64:
    """The refits' deviations ``x_i - x0`` (N, K) on the map displaced by draws of the
    field (module doc) around the refined answer ``x0``; none (0, K) where the model has no
    finite residuals or gradient there, the size is not defined (one band) or not positive,
    or a refit ends non-finite."""
    none = np.zeros((0, x0.size))
    r, jac = model.residuals(x0)
    if jac is None or not np.all(np.isfinite(r)) or not np.any(jac):
        return none
    unit = np.random.default_rng(SEED).standard_normal(
        (n_draws, model.bmap.direction_body.shape[0], 2)
    )
    s = warp_scale(model, x0, r, jac, unit)
    if not (np.isfinite(s) and s > 0):
        return none
    dev = [
        refit(dataclasses.replace(model, bmap=warped_map(model.bmap, s * u)), x0) - x0 for u in unit
    ]
    d = np.array(dev)
    return d if np.all(np.isfinite(d)) else none


def map_warp_covariance(model: SpinMisfit, x0: F64, n_draws: int = N_DRAWS) -> F64:
    """The parameters' covariance (K, K) from the map's error: the second moment of
    :func:`map_warp_deviations` with its axis block shrunk towards isotropic
    (:func:`.spin_axis_jackknife.shrunk_second_moment`); zeros where there are none."""
    d = map_warp_deviations(model, x0, n_draws)
    if d.shape[0] == 0:
        return np.zeros((x0.size, x0.size))
    return shrunk_second_moment(d)[0]


def covering_covariance(a: F64, b: F64) -> F64:
    """The covariance (K, K) whose ellipsoid covers those of ``a`` and ``b`` (K, K)
    (positive definite ``a``, semi-definite ``b``): ``a^1/2 U max(L, 1) U^T a^1/2`` with
    ``U L U^T`` the eigendecomposition of ``a^-1/2 b a^-1/2`` (in the basis where both are
    diagonal, the larger of the two variances on each axis: so ``C >= a`` and ``C >= b``,
    and ``C = a`` where ``b <= a``); ``a + b`` where ``a`` is not positive definite."""
    w, v = np.linalg.eigh(a)
    if not (np.all(np.isfinite(w)) and np.min(w) > 0):
        return np.asarray(a + b)
    half = (v * np.sqrt(w)) @ v.T
    inv_half = (v / np.sqrt(w)) @ v.T
    lam, u = np.linalg.eigh(inv_half @ b @ inv_half)
    return np.asarray(half @ (u * np.maximum(lam, 1.0)) @ u.T @ half)
