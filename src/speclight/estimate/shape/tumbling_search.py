"""Far starts for the torque-free fit: a coarse grid scored without optimisation, then
continuation from a short window to the whole light curve.

Random starts hit the narrow basin of the true state rarely (docs/shape.md, "Limits"), so
:func:`grid_starts` scores many states at once, using that a torque-free motion's attitude
is ``q(t) = q0 q_ref(t)`` where ``q_ref`` is the same motion started from the identity
(the body-frame rates do not depend on the attitude): for each dynamic (second moments
``u`` on a grid, body rates ``omega0`` from directions on a sphere times the rates of
:func:`grid_rates`: log-uniform over the period range and seeded from the light curves'
periodogram) one propagation serves every attitude ``q0`` of a
quasi-uniform set in SO(3), and the misfit of all of them is one array operation. The
grid is scored on a short window around ``t0`` (a turn or two: there the motion is close
to a uniform rotation and the rate error costs little phase), the best
:data:`N_KEEP` are refined there by least squares and carried, window by window
(each :data:`GROWTH` times longer), to the whole curve (continuation). It runs twice:
from a first window of 1.5 turns and from one holding 3 points per parameter
(:data:`POINTS_PER_PARAMETER`). Around a continuation's solutions,
:func:`local_draws` gives states to score for a neighbouring minimum (the hop).
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
#: Extra grid moments near the sphere ``u = 0``, triaxial, with the sorted moment ratios
#: (0.74, 0.89), (0.86, 0.94), (0.91, 0.96), (0.95, 0.98): there the grid's step of 1 in
#: ``u`` is a step of 0.3 or more in the ratios.
NEAR_SYMMETRIC_U = ((0.3, -0.3), (0.3, 0.15), (-0.2, -0.1), (0.1, 0.05))
#: Directions of the body rates on the grid (Fibonacci sphere).
N_DIRECTIONS = 26
#: Rates of the grid over the period range (log-uniform).
N_RATES = 6
#: Independent light-curve frequencies that seed grid rates (:func:`light_curve_frequencies`).
N_FREQUENCIES = 2
#: Periodogram frequencies per resolution ``1 / T`` of the longest curve.
OVERSAMPLING = 10
#: Harmonics (and subharmonics) of a stronger peak that do not count as independent.
MAX_HARMONIC = 4
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
#: The grid and the continuation run once for each entry: the first window
#: :data:`WINDOW_TURNS` turns wide, widened to hold at least this many points per fitted
#: parameter. On a short window wrong states fit as well as the truth and crowd it out
#: of the kept ones; on a long one the coarse grid has no state near enough to rank the
#: truth's basin first; which one keeps the truth varies from case to case, so both run
#: (BENCHMARKS.md, "Tumbling from far starts", seventh session).
POINTS_PER_PARAMETER = (0, 3)
#: States drawn around a local minimum to hop out of it (:func:`local_draws`).
HOP_DRAWS = 2000
#: Their spread, in standard deviations of the minimum's covariance.
HOP_SPREAD = 3.0
#: The best draws refined.
HOP_REFINE = 4


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


def window_schedule(time_s: F64, fastest_period_s: float, min_points: int = 0) -> list[float]:
    """Half widths [s] of the continuation's windows around ``t = 0``, the last covering
    every point: the first :data:`WINDOW_TURNS` turns of the fastest period wide, widened
    to hold ``min_points`` points (:data:`POINTS_PER_PARAMETER`)."""
    reach = float(np.max(np.abs(time_s)))
    distance = np.sort(np.abs(time_s))
    enough = float(distance[min(max(min_points, 1), distance.size) - 1])
    half = max(0.5 * WINDOW_TURNS * fastest_period_s, enough)
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


def searched_period_range_h(
    d: InversionData, min_period_h: float, max_period_h: float
) -> tuple[float, float]:
    """The periods the search covers [h]: ``min_period_h`` up to ``max_period_h`` or, when
    longer, the longest light curve's span (a body that turns once a curve still shows its
    turn there; the bench's slow draws lay beyond a fixed upper end)."""
    spans_s = [float(np.ptp(d.time_jd[d.curve == c])) * SECONDS_PER_DAY for c in range(d.n_curves)]
    return min_period_h, max(max_period_h, max(spans_s) / 3600.0)


def grid_moments() -> list[F64]:
    """The grid's second-moment parameters ``u``: :data:`GRID_U` squared and
    :data:`NEAR_SYMMETRIC_U`."""
    square = [np.array([u1, u2]) for u1 in GRID_U for u2 in GRID_U]
    return square + [np.array(u) for u in NEAR_SYMMETRIC_U]


def light_curve_frequencies(
    d: InversionData, min_period_h: float, max_period_h: float, n: int = N_FREQUENCIES
) -> F64:
    """The ``n`` strongest independent frequencies [Hz] of the light curves' periodogram.

    A tumbler's light curve is quasi-periodic with two fundamental frequencies, those of
    the precession and of the rotation (or nutation), and their combinations (Pravec et al.
    2005, Icarus 173, 108, doi:10.1016/j.icarus.2004.07.021). The power is the
    Lomb-Scargle periodogram (astropy, one harmonic, standard normalisation) of each light
    curve on its own (the gaps between curves would alias), summed with the curves' point
    counts as weights, from ``1 / max_period`` to ``4 / min_period`` (a four-fold light
    curve), at most the curves' Nyquist frequency, :data:`OVERSAMPLING` frequencies per
    resolution ``1 / T`` of the longest curve. Its local maxima, strongest first, are
    taken when no ratio ``a / b`` (``a, b <=`` :data:`MAX_HARMONIC`) to a frequency taken
    before lies within half a resolution: harmonics and subharmonics of one motion count
    once. Fewer than ``n`` when the periodogram has fewer such peaks.
    """
    from astropy.timeseries import LombScargle

    t_s = (d.time_jd - d.time_jd[0]) * SECONDS_PER_DAY
    curves = [np.flatnonzero(d.curve == c) for c in range(d.n_curves)]
    curves = [k for k in curves if k.size > 2 * MAX_HARMONIC]
    if not curves:
        return np.empty(0)
    span_s = max(float(np.ptp(t_s[k])) for k in curves)
    step_s = min(float(np.median(np.diff(t_s[k]))) for k in curves)
    f_hi = min(MAX_HARMONIC / (3600.0 * min_period_h), 0.5 / step_s)
    f_lo = 1.0 / (3600.0 * max_period_h)
    freq = np.arange(f_lo, f_hi, 1.0 / (OVERSAMPLING * span_s))
    if freq.size < 3:
        return np.empty(0)
    power = np.zeros(freq.size)
    for k in curves:
        ls = LombScargle(t_s[k], d.brightness[k], d.sigma[k])
        power += k.size * ls.power(freq, normalization="standard")
    peak = np.flatnonzero((power[1:-1] > power[:-2]) & (power[1:-1] >= power[2:])) + 1
    orders = np.arange(1, MAX_HARMONIC + 1)
    ratios = (orders[:, None] / orders[None, :]).ravel()
    taken: list[float] = []
    for i in peak[np.argsort(power[peak])[::-1]]:
        if all(np.min(np.abs(freq[i] - ratios * f)) > 0.5 / span_s for f in taken):
            taken.append(float(freq[i]))
        if len(taken) == n:
            break
    return np.array(taken)


def grid_rates(d: InversionData, min_period_h: float, max_period_h: float) -> F64:
    """Body rates [rad/s] of the grid: :data:`N_RATES` log-uniform over
    ``min_period_h..max_period_h``, and from each independent light-curve frequency ``f``
    (:func:`light_curve_frequencies`) the rates ``2 pi f`` and ``pi f`` (a light curve's
    strongest frequency is often twice the rotation's: a body shows two like halves a turn)
    that lie in the searched range (:func:`searched_period_range_h`: up to the longest
    curve's span). The log-uniform rates are not continued to the span: slow rates fit the
    short first window too easily and crowd out the right one (BENCHMARKS.md)."""
    lo_h, hi_h = searched_period_range_h(d, min_period_h, max_period_h)
    periods_s = 3600.0 * np.geomspace(min_period_h, max_period_h, N_RATES)
    f = light_curve_frequencies(d, lo_h, hi_h)
    seeded = np.concatenate([f, 0.5 * f])
    seeded = seeded[(seeded >= 1 / (3600.0 * hi_h)) & (seeded <= 1 / (3600.0 * lo_h))]
    return np.concatenate([2 * np.pi / periods_s, 2 * np.pi * seeded])


def grid_starts(
    d: InversionData,
    t_s: F64,
    light: LightModel,
    *,
    rates_rad_s: F64,
    rng: np.random.Generator,
    n_keep: int = N_KEEP,
) -> list[F64]:
    """The ``n_keep`` best grid states (module doc) for the points ``d`` at ``t_s`` [s]
    from ``t0`` under the light model ``light`` (:mod:`.tumbling_light`), the body rates'
    magnitudes ``rates_rad_s`` [rad/s] (:func:`grid_rates`), as the fit's state vectors
    (rotation vector, body rates [rad/s], ``u``, log scale)."""
    rot = Rotation.random(N_ATTITUDES, rng=rng)
    r_mat = rot.as_matrix()  # (S, 3, 3) body-to-ecliptic at t0
    sun = np.einsum("skj,nk->snj", r_mat, d.sun_ecliptic)  # R^T s, (S, N, 3)
    obs = np.einsum("skj,nk->snj", r_mat, d.observer_ecliptic)
    chp = np.tile(d.cos_half_phase, N_ATTITUDES)
    best: list[tuple[float, F64]] = []
    for u in grid_moments():
        moments = moments_from_u(u)
        for direction in fibonacci_sphere(N_DIRECTIONS):
            for rate in rates_rad_s:
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


def local_draws(
    x: F64,
    jacobian: F64,
    residuals: F64,
    rng: np.random.Generator,
    *,
    n: int = HOP_DRAWS,
    spread: float = HOP_SPREAD,
) -> F64:
    """(n, p) states drawn around the least-squares solution ``x`` (p,) from a normal of
    ``spread`` times its covariance ``s^2 (J^T J)^+`` (``J`` the (N, p) ``jacobian``,
    ``s^2`` the ``residuals``' (N,) mean square per degree of freedom).

    A fit that ends in the right family but a turn of one angle off (a local minimum
    next to the truth's: a nutation or precession phase slipped over the curve, or the
    cycle count over a gap between curves wrong) lies within a few of its standard
    deviations of the truth, along the directions the data constrain least; scoring
    draws there and refining the best finds the neighbouring minima that a local
    optimiser started at ``x`` cannot reach (BENCHMARKS.md)."""
    dof = max(residuals.size - x.size, 1)
    cov = float(np.sum(residuals**2)) / dof * np.linalg.pinv(jacobian.T @ jacobian)
    w, v = np.linalg.eigh(0.5 * (cov + cov.T))
    root = v * np.sqrt(np.clip(w, 0.0, None))
    return np.asarray(x + spread * rng.normal(size=(n, x.size)) @ root.T)
