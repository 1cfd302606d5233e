"""Tumbling (non-principal-axis) rotation: the torque-free state fitted to light curves.

The body's light model is given (``light``, :class:`.tumbling_light.LightModel`: e.g. the
convex model of the scenario's mesh, or its reflectivity map); the state at ``t0`` is
fitted: the attitude ``q0`` (body to ecliptic J2000, as a rotation vector), the body rates
``omega0`` [rad/s] and the principal moments (body axes principal) as ``I = tr(M) 1 - M``
of second moments ``M = diag(exp(u1), exp(u2), 1)`` (any ``u`` gives moments that satisfy
the triangle inequality of a real body), and for calibrated data a log-scale of the
brightness. The attitude at each epoch comes from speclight's torque-free propagation
(:func:`speclight.attitude.torque_free_attitude`, closed form), the brightness from the
light model (:mod:`.tumbling_light`: the convex model of the EGI, without shadows, or the
target's reflectivity map, with them).

Light curves do not fix the state uniquely (Kaasalainen 2001, A&A 376, 302; Pravec et al.
2005, Icarus 173, 108): a body symmetry maps a state onto another with the same light
curve, and different precession/rotation combinations fit nearly as well. So the fit is
multi-start (:data:`N_STARTS` random states: uniform attitudes, rates from the period range,
second moments log-uniform), each run by trust-region least squares
(:func:`scipy.optimize.least_squares`, gradient from 2-point differences), and every
solution within ``chi2_min + delta s^2`` (``delta`` the 99 % point of chi-square with as many
degrees of freedom as parameters) is kept. Solutions are grouped into families by what
a body symmetry does not change: the direction of the angular momentum in the ecliptic
frame (within :data:`FAMILY_ANGLE_DEG`), the rotation rate ``|H| / I_max`` and the sorted
moment ratios (within :data:`FAMILY_RELATIVE`); every family is reported.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import stats
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from speclight.attitude import torque_free_attitude
from speclight.attitude.quaternion import quat_conjugate, quat_multiply, quat_rotate
from speclight.estimate.shape.convex_model import relative_residuals
from speclight.estimate.shape.ecliptic import angular_distance_deg
from speclight.estimate.shape.inversion_data import InversionData
from speclight.estimate.shape.tumbling_light import LightModel
from speclight.estimate.shape.tumbling_mirror import mirror_plane, mirror_state
from speclight.estimate.shape.tumbling_principal import ALPHA as PRINCIPAL_ALPHA
from speclight.estimate.shape.tumbling_principal import lag1_correlation, principal_axis_test
from speclight.estimate.shape.tumbling_search import (
    HOP_REFINE,
    N_CARRY,
    POINTS_PER_PARAMETER,
    grid_rates,
    grid_starts,
    local_draws,
    moments_from_u,
    searched_period_range_h,
    window_schedule,
)
from speclight.estimate.shape.tumbling_state import TumblingState
from speclight.estimate.shape.tumbling_uncertainty import rate_and_ratio_std

F64 = NDArray[np.float64]
N_STARTS = 32
FAMILY_ANGLE_DEG = 10.0
FAMILY_RELATIVE = 0.05
SECONDS_PER_DAY = 86400.0
IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])
MOMENT_SPREAD = 2.0  # second moments drawn log-uniform within e^(+-2)
MOMENT_BOUND = 6.0  # and kept within e^(+-6) (a needle or a disk: moment ratios to 5e-3)
MAX_EVALUATIONS = 200
FIRST_EVALUATIONS = 60  # in the continuation's first window (many grid starts)
N_SEEDS = 6
PHASE_DRIFT = 0.2  # turns of phase drift over the gap between rate-scale trials
RATE_SPAN = 0.03  # relative rate error of a seed curve's solution covered by the trials


@dataclass(frozen=True)
class TumblingFit:
    """Result of :func:`fit_tumbling`: ``families`` (each a list of states, lowest chi-square
    first; families ordered by their best), ``worst_kept_chi2`` (the largest chi-square kept),
    ``solutions`` (every final fit), ``t0_jd`` (the states' epoch [d]), and the test
    against a principal-axis rotation (its chi-square and the p-value)."""

    families: list[list[TumblingState]]
    worst_kept_chi2: float
    solutions: list[TumblingState]
    t0_jd: float
    principal_axis_chi2: float = float("nan")
    p_value: float = float("nan")
    searched_period_h: tuple[float, float] = (float("nan"), float("nan"))

    @property
    def detected(self) -> bool:
        """True when the best state fits significantly better than a rotation about a
        principal axis (:mod:`.tumbling_principal`): only then is it a tumbling state."""
        return bool(self.p_value < PRINCIPAL_ALPHA)


class _Problem:
    def __init__(self, data: InversionData, light: LightModel, t0_jd: float) -> None:
        self.data, self.light = data, light
        self.t0_jd = t0_jd
        self.t_s = (data.time_jd - t0_jd) * SECONDS_PER_DAY
        self.calibrated = bool(np.any(data.calibrated))
        self._motion_key = b""
        self._motion = np.empty((0, 4))

    @property
    def n_parameters(self) -> int:
        """Parameters of the state vector: attitude, rates, ``u`` and, calibrated, the scale."""
        return 9 if self.calibrated else 8

    def bounds(self) -> tuple[F64, F64]:
        """Lower and upper bounds of the state vector (``u`` within :data:`MOMENT_BOUND`)."""
        lower, upper = np.full(self.n_parameters, -np.inf), np.full(self.n_parameters, np.inf)
        lower[6:8], upper[6:8] = -MOMENT_BOUND, MOMENT_BOUND
        return lower, upper

    def state(self, x: F64) -> tuple[F64, F64, F64, float]:
        q = Rotation.from_rotvec(x[:3]).as_quat(scalar_first=True)
        scale = float(np.exp(x[8])) if self.calibrated else 1.0
        return q, x[3:6], moments_from_u(x[6:8]), scale

    def motion(self, x: F64) -> F64:
        """(N, 4) attitudes ``q_ref(t)`` of the motion of ``x`` started from the identity
        (body at ``t`` to body at ``t0``): the attitude is ``q0 q_ref(t)``, so a change of
        ``q0`` (or of the scale) needs no new propagation. The last is kept."""
        key = x[3:8].tobytes()
        if key != self._motion_key:
            _, w0, moments, _ = self.state(x)
            self._motion, _ = torque_free_attitude(self.t_s, moments, IDENTITY, w0)
            self._motion_key = key
        return self._motion

    def residuals(self, x: F64) -> F64:
        return self._residuals(x, self.motion(x))

    def _residuals(self, x: F64, motion: F64) -> F64:
        q0, _, _, scale = self.state(x)
        qc = quat_conjugate(quat_multiply(q0, motion))
        s_b = quat_rotate(qc, self.data.sun_ecliptic)
        o_b = quat_rotate(qc, self.data.observer_ecliptic)
        lum = scale * self.light(s_b, o_b, self.data.cos_half_phase)
        return relative_residuals(self.data, lum)

    def jacobian(self, x: F64, lower: F64, upper: F64) -> F64:
        """Forward differences of :meth:`residuals` (scipy's 2-point rule: step
        ``sqrt(eps) max(1, |x_i|)``, backwards at a bound), the attitude and scale
        columns on the motion of ``x`` (no propagation: 5 propagations where 8 were)."""
        motion = self.motion(x)
        f0 = self._residuals(x, motion)
        jac = np.empty((f0.size, x.size))
        for i in range(x.size):
            h = np.sqrt(np.finfo(float).eps) * max(1.0, abs(x[i])) * (1.0 if x[i] >= 0 else -1.0)
            if not lower[i] <= x[i] + h <= upper[i]:
                h = -h
            xh = x.copy()
            xh[i] += h
            h = xh[i] - x[i]
            if 3 <= i < 8:
                jac[:, i] = (self._residuals(xh, self.motion(xh)) - f0) / h
            else:
                jac[:, i] = (self._residuals(xh, motion) - f0) / h
        return jac


def fit_tumbling(
    data: InversionData,
    light: LightModel,
    *,
    min_period_h: float,
    max_period_h: float,
    n_starts: int = N_STARTS,
    seed: int = 0,
    initial_states: list[TumblingState] | None = None,
    t0_jd: float | None = None,
    rate_span: float = RATE_SPAN,
    grid: bool = True,
) -> TumblingFit:
    """Multi-start fit of the torque-free state and its families (module doc).

    The state's epoch ``t0`` is the middle of the longest light curve (the seed). Stage 1:
    ``n_starts`` random starts and the grid's (:mod:`.tumbling_search`, two
    continuations) fitted to the seed curve alone (a few rotations: a smoother misfit);
    around each of its solutions within its threshold (at most :data:`N_SEEDS`, one per
    family), states drawn from the solution's covariance are scored and the best refined
    (the hop, :func:`.tumbling_search.local_draws`: a neighbouring minimum a turn of one
    angle away). Stage 2: the seeds, now the best of the hop's families, are carried to
    all curves; over a gap of ``T`` the
    rotation phase drifts by ``T / P`` turns per unit of relative rate error, so each starts
    at rate scales ``1 + j dc``, ``dc =`` :data:`PHASE_DRIFT` ``P / T``, ``|j dc| <=``
    :data:`RATE_SPAN` (a torque-free motion with its rates scaled by ``c`` is the same
    motion ``c`` times faster), and from the hop's draws around each seed (its covariance
    on the seed curve) scored on all curves: where the gap's cycle count depends on more
    than the rate (the moments set the second frequency), the rate scales alone miss it.
    The lowest of all is kept as in stage 1. Last, the
    mirror image of each kept family's best (at most :data:`N_SEEDS`;
    :mod:`.tumbling_mirror`) is fitted to all curves and joins the solutions.

    ``rate_span``: the relative rate error covered in stage 2 (default :data:`RATE_SPAN`).
    ``initial_states`` (at ``t0_jd``, default the seed curve's middle) are tried before the
    random starts: a prior (e.g. the scenario's attitude) narrows a search that random
    starts alone rarely win (docs/shape.md, "Limits").
    """
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):  # small matrices (shape_run.py)
        return _fit_tumbling(
            data,
            light,
            min_period_h,
            max_period_h,
            n_starts,
            seed,
            initial_states,
            t0_jd,
            rate_span,
            grid,
        )


def _fit_tumbling(
    data: InversionData,
    light: LightModel,
    min_period_h: float,
    max_period_h: float,
    n_starts: int,
    seed: int,
    initial_states: list[TumblingState] | None,
    t0_jd: float | None,
    rate_span: float,
    grid: bool,
) -> TumblingFit:
    counts = np.bincount(data.curve)
    seed_curve = int(np.argmax(counts))
    in_seed = np.flatnonzero(data.curve == seed_curve)
    if t0_jd is None:
        t0_jd = float(np.mean(data.time_jd[in_seed][[0, -1]]))
    rng = np.random.default_rng(seed)
    seed_data = data.subset(in_seed)
    seed_prob = _Problem(seed_data, light, t0_jd)
    searched = searched_period_range_h(data, min_period_h, max_period_h)
    x_starts = [_state_vector(s, 1.0) for s in initial_states or []]
    x_starts += [_random_start(rng, *searched) for _ in range(n_starts)]
    rates = grid_rates(data, min_period_h, max_period_h) if grid else np.empty(0)
    first = _continued(seed_prob, x_starts, min_period_h, rates, rng)
    seeds = [fam[0] for fam in _families(_within(first, seed_prob))][:N_SEEDS]
    first = sorted(first + _hopped(seed_prob, seed_prob, seeds, rng), key=lambda s: s.chi2)
    seeds = [fam[0] for fam in _families(_within(first, seed_prob))][:N_SEEDS]
    prob = _Problem(data, light, t0_jd)
    if data.n_curves == 1:
        final = first
    else:
        gap_s = float(np.ptp(data.time_jd)) * SECONDS_PER_DAY
        x_next = []
        for sol in seeds:
            period_s = 2 * np.pi / sol.rate_rad_s
            dc = PHASE_DRIFT * period_s / gap_s
            for j in np.arange(-np.floor(rate_span / dc), np.floor(rate_span / dc) + 1):
                x_next.append(_state_vector(sol, 1.0 + j * dc))
        final = sorted(
            _fit_all(prob, x_next) + _hopped(seed_prob, prob, seeds, rng), key=lambda s: s.chi2
        )
    # each family's mirror image (tumbling_mirror.py) fitted too: a start the search
    # rarely reaches, as good as the family where the geometry is nearly coplanar
    normal, _ = mirror_plane(data.sun_ecliptic, data.observer_ecliptic)
    mirrors = [mirror_state(f[0], normal) for f in _families(_within(final, prob))]
    final = sorted(
        final + _fit_all(prob, [_state_vector(m, 1.0) for m in mirrors[:N_SEEDS]]),
        key=lambda s: s.chi2,
    )
    kept = _within(final, prob)
    n_par = prob.n_parameters
    chi_pa, p = principal_axis_test(prob.residuals, _state_vector(kept[0], 1.0)[:n_par], n_par)
    return TumblingFit(_families(kept), kept[-1].chi2, final, t0_jd, chi_pa, p, searched)


def _continued(
    prob: _Problem,
    x_starts: list[F64],
    min_period_h: float,
    grid_rates_rad_s: F64,
    rng: np.random.Generator,
) -> list[TumblingState]:
    """The starts (plus the grid's at the rates ``grid_rates_rad_s``, none when empty,
    :mod:`.tumbling_search`) fitted to windows around ``t0`` growing to the whole of
    ``prob``'s points (continuation); the best of each window's :data:`N_CARRY` best
    families (and every given start) go on to the next. With a grid, once for each first
    window of :data:`.tumbling_search.POINTS_PER_PARAMETER` (the starts in the first
    only), the solutions of all together."""
    n_par = prob.n_parameters
    passes = POINTS_PER_PARAMETER if grid_rates_rad_s.size else POINTS_PER_PARAMETER[:1]
    sols: list[TumblingState] = []
    for i, per_parameter in enumerate(passes):
        halves = window_schedule(prob.t_s, 3600.0 * min_period_h, per_parameter * n_par)
        sols += _continued_once(prob, x_starts if i == 0 else [], halves, grid_rates_rad_s, rng)
    return sorted(sols, key=lambda s: s.chi2)


def _continued_once(
    prob: _Problem,
    x_starts: list[F64],
    halves: list[float],
    grid_rates_rad_s: F64,
    rng: np.random.Generator,
) -> list[TumblingState]:
    """One continuation of :func:`_continued` through the windows ``halves`` [s]."""
    d, t0_jd = prob.data, prob.t0_jd
    starts = list(x_starts)
    sols: list[TumblingState] = []
    for k, half in enumerate(halves):
        index = np.flatnonzero(np.abs(prob.t_s) <= half)
        window = _Problem(d.subset(index), prob.light, t0_jd)
        if k == 0 and grid_rates_rad_s.size:
            starts += grid_starts(
                window.data, window.t_s, prob.light, rates_rad_s=grid_rates_rad_s, rng=rng
            )
        sols = _fit_all(window, starts, FIRST_EVALUATIONS if k == 0 else MAX_EVALUATIONS)
        carried = [fam[0] for fam in _families(sols)][: max(N_CARRY, len(x_starts))]
        starts = [_state_vector(s, 1.0) for s in carried]
    return sols


def _hopped(
    around: _Problem, prob: _Problem, states: list[TumblingState], rng: np.random.Generator
) -> list[TumblingState]:
    """For each state, draws around it from its covariance on ``around``'s points
    (:func:`.tumbling_search.local_draws`), scored on ``prob``'s, the best
    :data:`.tumbling_search.HOP_REFINE` of them fitted to ``prob``."""
    n_par = prob.n_parameters
    lower, upper = prob.bounds()
    starts = []
    for s in states:
        x = _state_vector(s, 1.0)[:n_par]
        draws = local_draws(x, around.jacobian(x, lower, upper), around.residuals(x), rng)
        draws[:, 6:8] = np.clip(draws[:, 6:8], -MOMENT_BOUND, MOMENT_BOUND)
        chi2 = np.array([np.sum(prob.residuals(v) ** 2) for v in draws])
        starts += [np.append(draws[i], 0.0) for i in np.argsort(chi2)[:HOP_REFINE]]
    return _fit_all(prob, starts)


def _random_start(rng: np.random.Generator, min_period_h: float, max_period_h: float) -> F64:
    period_s = 3600.0 * np.exp(rng.uniform(np.log(min_period_h), np.log(max_period_h)))
    return np.concatenate(
        [
            Rotation.random(rng=rng).as_rotvec(),
            2 * np.pi / period_s * _unit(rng.normal(size=3)),
            rng.uniform(-MOMENT_SPREAD, MOMENT_SPREAD, 2),
            [0.0],
        ]
    )


def _state_vector(s: TumblingState, rate_scale: float) -> F64:
    m = 0.5 * np.sum(s.moments) - s.moments  # second moments of I = tr(M) 1 - M
    u = np.log(np.clip(m[:2] / m[2], np.exp(-MOMENT_BOUND), np.exp(MOMENT_BOUND)))
    return np.concatenate(
        [
            Rotation.from_quat(s.q0, scalar_first=True).as_rotvec(),
            s.omega0_body_rad_s * rate_scale,
            u,
            [np.log(s.scale)],
        ]
    )


def _fit_all(
    prob: _Problem, starts: list[F64], max_evaluations: int = MAX_EVALUATIONS
) -> list[TumblingState]:
    n_par = prob.n_parameters
    lower, upper = prob.bounds()
    out = []
    for x0 in starts:
        x = x0[:n_par].copy()
        x[6:8] = np.clip(x[6:8], -MOMENT_BOUND, MOMENT_BOUND)
        res = least_squares(
            prob.residuals,
            x,
            jac=lambda v: prob.jacobian(v, lower, upper),
            bounds=(lower, upper),
            method="trf",
            x_scale="jac",
            max_nfev=max_evaluations,
        )
        q0, w0, moments, scale = prob.state(np.append(res.x, 0.0)[:9])
        std = rate_and_ratio_std(res.x, res.jac, res.fun)
        out.append(TumblingState(q0, w0, moments, float(2.0 * res.cost), scale, std))
    out.sort(key=lambda s: s.chi2)
    return out


def _within(states: list[TumblingState], prob: _Problem) -> list[TumblingState]:
    """The states within ``chi2_min + delta s^2`` (module doc), ``s^2`` the best's
    residual variance times ``(1 + rho) / (1 - rho)``, ``rho`` its residuals' lag-1
    correlation (model error: fewer independent points, as in :mod:`.tumbling_principal`)."""
    n_par = prob.n_parameters
    rho = max(lag1_correlation(prob.residuals(_state_vector(states[0], 1.0)[:n_par])), 0.0)
    s2 = states[0].chi2 / max(prob.data.n_points - n_par, 1) * (1 + rho) / (1 - rho)
    threshold = states[0].chi2 + float(stats.chi2.ppf(0.99, n_par)) * s2
    return [s for s in states if s.chi2 <= threshold]


def _unit(v: F64) -> F64:
    return np.asarray(v / np.linalg.norm(v))


def same_family(a: TumblingState, b: TumblingState) -> bool:
    """True when two states agree in what a body symmetry leaves (module doc)."""
    return bool(
        angular_distance_deg(a.momentum_direction, b.momentum_direction) <= FAMILY_ANGLE_DEG
        and abs(a.rate_rad_s / b.rate_rad_s - 1.0) <= FAMILY_RELATIVE
        and np.all(np.abs(a.moment_ratios - b.moment_ratios) <= FAMILY_RELATIVE)
    )


def _families(states: list[TumblingState]) -> list[list[TumblingState]]:
    families: list[list[TumblingState]] = []
    for s in states:
        for fam in families:
            if same_family(fam[0], s):
                fam.append(s)
                break
        else:
            families.append([s])
    return families
