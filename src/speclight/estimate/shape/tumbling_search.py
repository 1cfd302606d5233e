"""Far starts for the torque-free fit: a coarse grid scored without optimisation, then
continuation from a short window to the whole light curve.

Random starts hit the narrow basin of the true state rarely (docs/shape.md, "Limits"), so
:func:`grid_starts` scores many states at once, using that a torque-free motion's attitude
is ``q(t) = q0 q_ref(t)`` where ``q_ref`` is the same motion started from the identity
(the body-frame rates do not depend on the attitude): for each dynamic (second moments
``u`` on a grid, body rates ``omega0`` from directions on a sphere times rates spread
log-uniform over the period range) one propagation serves every attitude ``q0`` of a
quasi-uniform set in SO(3), and the misfit of all of them is one array operation. The
grid is scored on a short window around ``t0`` (a turn or two: there the motion is close
to a uniform rotation and the rate error costs little phase), the best
:data:`N_KEEP` are refined there by least squares and carried, window by window
(each :data:`GROWTH` times longer), to the whole curve (continuation).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from speclight.attitude import torque_free_attitude
from speclight.attitude.quaternion import quat_to_matrix
from speclight.estimate.shape.inversion_data import InversionData
from speclight.estimate.shape.tumbling_light import LightModel

F64 = NDArray[np.float64]
SECONDS_PER_DAY = 86400.0
#: Second-moment parameters ``u`` of the grid (each of the two), [1].
GRID_U = (-1.0, 0.0, 1.0)
#: Directions of the body rates on the grid (Fibonacci sphere).
N_DIRECTIONS = 26
#: Rates of the grid over the period range (log-uniform).
N_RATES = 6
#: Attitudes of the grid (quasi-uniform in SO(3), fixed seed).
N_ATTITUDES = 300
#: Grid states refined in the first window.
N_KEEP = 24
#: States carried from one window to the next.
N_CARRY = 24
#: Turns of the fastest grid rate in the first window.
WINDOW_TURNS = 1.5
#: Each window this many times longer than the one before.
GROWTH = 2.0


def moments_from_u(u: F64) -> F64:
    """Principal moments ``I = tr(M) 1 - M`` (largest 1) of second moments
    ``M = diag(exp(u1), exp(u2), 1)`` [1]."""
    m = np.array([np.exp(u[0]), np.exp(u[1]), 1.0])
    inertia = np.sum(m) - m
    return np.asarray(inertia / np.max(inertia))


def fibonacci_sphere(n: int) -> F64:
    """(n, 3) quasi-uniform unit vectors (the Fibonacci lattice)."""
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    phi = np.pi * (1.0 + np.sqrt(5.0)) * k
    r = np.sqrt(1.0 - z**2)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def window_schedule(time_s: F64, fastest_period_s: float) -> list[float]:
    """Half widths [s] of the continuation's windows around ``t = 0``, the last covering
    every point."""
    reach = float(np.max(np.abs(time_s)))
    half = 0.5 * WINDOW_TURNS * fastest_period_s
    out = []
    while half < reach:
        out.append(half)
        half *= GROWTH
    return [*out, reach]


def _misfit(d: InversionData, lum: F64) -> F64:
    """Chi-square of model brightness rows ``lum`` (S, N) against ``d``: relative curves
    scaled by ``ybar / Lbar``, calibrated ones by their best common factor."""
    w = 1.0 / d.sigma
    model = np.empty_like(lum)
    cal = d.calibrated[d.curve]
    for c in range(d.n_curves):
        k = d.curve == c
        if not d.calibrated[c]:
            lbar = np.maximum(np.mean(lum[:, k], axis=1, keepdims=True), 1e-300)
            model[:, k] = lum[:, k] * np.mean(d.brightness[k]) / lbar
    if np.any(cal):
        lc, yc, wc = lum[:, cal], d.brightness[cal], w[cal] ** 2
        scale = (lc @ (wc * yc)) / np.maximum((lc**2) @ wc, 1e-300)
        model[:, cal] = lc * scale[:, None]
    return np.asarray(np.sum(((d.brightness - model) * w) ** 2, axis=1))


def grid_starts(
    d: InversionData,
    t_s: F64,
    light: LightModel,
    *,
    min_period_h: float,
    max_period_h: float,
    rng: np.random.Generator,
    n_keep: int = N_KEEP,
) -> list[F64]:
    """The ``n_keep`` best grid states (module doc) for the points ``d`` at ``t_s`` [s]
    from ``t0`` under the light model ``light`` (:mod:`.tumbling_light`), as the fit's
    state vectors (rotation vector, body rates [rad/s], ``u``, log scale)."""
    rot = Rotation.random(N_ATTITUDES, rng=rng)
    r_mat = rot.as_matrix()  # (S, 3, 3) body-to-ecliptic at t0
    sun = np.einsum("skj,nk->snj", r_mat, d.sun_ecliptic)  # R^T s, (S, N, 3)
    obs = np.einsum("skj,nk->snj", r_mat, d.observer_ecliptic)
    chp = np.tile(d.cos_half_phase, N_ATTITUDES)
    rates = 2 * np.pi / (3600.0 * np.geomspace(min_period_h, max_period_h, N_RATES))
    best: list[tuple[float, F64]] = []
    for u1 in GRID_U:
        for u2 in GRID_U:
            u = np.array([u1, u2])
            moments = moments_from_u(u)
            for direction in fibonacci_sphere(N_DIRECTIONS):
                for rate in rates:
                    w0 = rate * direction
                    q, _ = torque_free_attitude(t_s, moments, np.array([1.0, 0, 0, 0]), w0)
                    m_ref = quat_to_matrix(q)  # (N, 3, 3) body at t to body at t0
                    s_b = np.einsum("nkj,snk->snj", m_ref, sun).reshape(-1, 3)
                    o_b = np.einsum("nkj,snk->snj", m_ref, obs).reshape(-1, 3)
                    lum = light(s_b, o_b, chp)
                    chi2 = _misfit(d, lum.reshape(N_ATTITUDES, -1))
                    for s in np.argsort(chi2)[:n_keep]:
                        x = np.concatenate([rot[int(s)].as_rotvec(), w0, u, [0.0]])
                        best.append((float(chi2[s]), x))
            best = sorted(best, key=lambda b: b[0])[: 4 * n_keep]
    return [x for _, x in _distinct(best, n_keep)]


def _distinct(scored: list[tuple[float, F64]], n: int) -> list[tuple[float, F64]]:
    """The ``n`` lowest, at most two per dynamic (rates and moments)."""
    out: list[tuple[float, F64]] = []
    for c, x in scored:
        same = sum(np.allclose(x[3:8], y[3:8]) for _, y in out)
        if same < 2:
            out.append((c, x))
        if len(out) == n:
            break
    return out
