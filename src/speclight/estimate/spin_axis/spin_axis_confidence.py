"""How well the data pin the spin axis: sigmas, a confidence region, and what cannot be trusted.

**Sigmas** (``method="jackknife-warp"``, the default since 2026-12-05): the covariance that
covers (:func:`.spin_axis_map_error.covering_covariance`: the larger of the two in their
common eigenbasis) two estimates of the same error: the sandwich below plus the
delete-a-block jackknife's spread (:func:`.spin_axis_jackknife.jackknife_refits`) with its
axis block shrunk towards isotropic by Ledoit and Wolf's intensity
(:func:`.spin_axis_jackknife.shrunk_jackknife_spread`), and the sandwich plus the map's own
error as a random displacement of its directions, sized from the residuals and propagated
by refits (:func:`.spin_axis_map_error.map_warp_covariance`). The jackknife sees what the
residuals along the pass do to the answer; the field sees what a map that misplaces its
features by a fraction of a pixel does to it, an error epochs in the same map cells share
and the jackknife over time blocks does not see. Over blind draws of three seeds (the third
not tuned on) error / sigma has standard deviations east / north 0.76 / 0.78, 0.86 / 1.29
and 0.77 / 1.06, the 95 % region holding the truth in 0.96, 0.95 and 0.93 of the draws
(BENCHMARKS.md "Spin-axis calibration: the map's error as a field"), against 1.15 / 1.03,
1.41 / 2.19 and 1.53 / 1.39 (0.93, 0.74, 0.71) for ``"jackknife-shrunk"`` (the sandwich
plus the shrunk jackknife alone, the default before); about twice its CPU.
``"sandwich-warp"`` is the sandwich plus the field (no jackknife: 0.83 / 0.85, 1.22 / 1.92,
0.92 / 1.18), ``"jackknife"`` the sandwich plus the unshrunk jackknife (ten refits cannot
resolve the axis block's shape: a thin ellipse, the map's error 19 sigma across it),
``"jackknife-map"`` that plus the half-resolution term below, ``"sandwich"`` the sandwich
alone.
With a free period the axis sigmas are the marginal ones over it (the axis block of the
covariance of all the parameters; every refit frees the period too) and the note says what
the bench measured then (:data:`FREE_PERIOD_NOTE`).

**Sandwich** (White 1980, Econometrica 48, 817, doi:10.2307/1912934;
Newey & West 1987, Econometrica 55, 703, doi:10.2307/1913610): at the refined solution the
misfit ``sum r^2`` has the Gauss-Newton Hessian ``2 A``, ``A = J^T J`` (the analytic
Jacobian of :class:`.spin_axis_gradient.SpinMisfit`, parameters: the axis's tangent
rotation east and north, the phase and, with a free period, the extra turn over the pass).
The residuals hold the noise and the map's own error, correlated across the bands of one
epoch and over neighbouring epochs, so the covariance is ``C = A^-1 S A^-1`` with ``S`` the
long-run covariance of the per-epoch scores ``g_t = sum_b J_tb r_tb``: Bartlett weights up
to a lag chosen from the scores' lag-1 correlation (Andrews 1991, Econometrica 59, 817,
doi:10.2307/2938229, eq. 6.4). No noise level is assumed; where the residuals are white
this is the usual ``sigma^2 (J^T J)^-1``.

**The map at half its resolution** (``method="jackknife-map"``, not used): the answer's shift
on the map at half its resolution over 3 as an isotropic variance on the axis
(:func:`.spin_axis_jackknife.map_error_covariance`): no measure of the map's error (its
components correlate -0.45 to -0.02 with the truth-map refit's; BENCHMARKS.md).

**Region**: with ``C_aa`` the axis block of ``C`` and ``(A^-1)_aa`` that of ``A^-1``, a
misfit rise of ``Delta e`` over the grid (the phase minimised, as the surface is) is
``Delta chi^2 = Delta e / c`` with ``c = tr(C_aa (A^-1)_aa^-1) / 2`` (``c`` is the misfit
per unit chi-square; where ``S`` is proportional to ``A`` this is exact). The cells with
``Delta chi^2 <= 5.99`` (95 %, two parameters) form the 95 % region, those ``<= 2.30`` the
68 % region; their share of the sphere and their farthest cell from the refined axis are
reported, so a second minimum the data do not exclude is seen.

**What cannot be trusted**, said in ``note``:

* a **flat surface**: the median misfit over the sphere below :data:`FLAT_CONTRAST` times
  the best, or a 95 % region over :data:`MAX_REGION_FRACTION` of the sphere, or an axis
  sigma over :data:`MAX_SIGMA_DEG`: the data do not constrain the axis (a Lambertian
  sphere's light curve is the same about every axis);
* a **second region**: cells of the 95 % region farther than :data:`SECOND_REGION_DEG` from
  the refined axis (the mirror is not excluded);
* a **misfit far above the noise**: the refined misfit over :data:`MAX_NOISE_RATIO` times the
  noise floor, the misfit noise alone would give (each band's noise variance of the
  mean-normalised curve, from the second differences of the measured curve,
  ``var(y_{t-1} - 2 y_t + y_{t+1}) = 6 sigma^2`` for white noise, robustly by the median
  absolute deviation; averaged over the bands): a wrong period, map or spin model.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.estimate.spin_axis.spin_axis_gradient import SpinMisfit
from speclight.estimate.spin_axis.spin_axis_jackknife import (
    JACKKNIFE_BLOCKS as JACKKNIFE_BLOCKS,  # the period check's blocks too
)
from speclight.estimate.spin_axis.spin_axis_jackknife import (
    jackknife_covariance,
    jackknife_refits,
    map_error_covariance,
    shrunk_jackknife_spread,
)
from speclight.estimate.spin_axis.spin_axis_lookup import EpochGeometry, angular_distance_deg
from speclight.estimate.spin_axis.spin_axis_map_error import (
    covering_covariance,
    map_warp_covariance,
)
from speclight.maps.map_lookup import ReflectivityMap

F64 = NDArray[np.float64]
#: Delta chi-square of the 68.3 % and 95 % regions of two parameters (chi-square quantiles).
DCHI2_68, DCHI2_95 = 2.2957, 5.9915
#: Median misfit over the sphere below this times the best: a flat surface.
FLAT_CONTRAST = 1.25
#: A 95 % region over this share of the sphere: the axis is not constrained.
MAX_REGION_FRACTION = 0.05
#: An axis sigma over this [deg]: the axis is not constrained.
MAX_SIGMA_DEG = 30.0
#: 95 % cells farther than this from the refined axis [deg]: a second region.
SECOND_REGION_DEG = 20.0
#: Refined misfit over this times the noise floor: flagged.
MAX_NOISE_RATIO = 10.0
#: Refined misfit over this times the noise floor (and up to :data:`MAX_NOISE_RATIO`): the
#: model's own error dominates the residuals; said after the sigmas (BENCHMARKS.md
#: "Spin-axis calibration: the map's error and the shrunk jackknife": the map's error is
#: then nearly the whole error and the sigmas may understate it).
MODEL_ERROR_RATIO = 2.0
#: The covariance of :func:`axis_confidence` unless another is asked for (module doc).
DEFAULT_METHOD = "jackknife-warp"
#: How the note of a flat surface starts.
FLAT_NOTE = "the data do not constrain the axis"
#: What the calibration bench showed of the sigmas with a free period (said after them;
#: BENCHMARKS.md "Spin-axis calibration: a free period").
FREE_PERIOD_NOTE = (
    "the period free: the sigmas are marginal over it (on the calibration bench, the period "
    "given 1-4 % off, error / sigma standard deviations east / north 0.97 / 0.90 and "
    "0.93 / 0.68 on 14 and 15 draws of two seeds, the truth in the 95 % region in all; "
    "1.89 / 1.15 on 8 draws of a third, one 5 sigma off; "
    "docs/spin-axis.md, Sigmas)"
)
#: The tangent rotation ``x[:2]`` to the axis's (east, north) offset (:func:`_sigmas`).
EAST_NORTH = np.array([[0.0, 1.0], [-1.0, 0.0]])


@dataclass
class AxisConfidence:
    """Uncertainties of a refined spin axis and what the misfit surface says (module doc).

    Angles in degrees; ``east``/``north`` are the tangent-plane directions at the refined
    axis (east: increasing RA, ``sigma_east_deg`` is ``sigma_RA cos(Dec)``).
    """

    sigma_east_deg: float = float("nan")
    sigma_north_deg: float = float("nan")
    correlation_east_north: float = float("nan")
    sigma_axis_deg: float = float("nan")  # sqrt of the larger eigenvalue of the axis block
    sigma_phase_deg: float = float("nan")
    sigma_period_s: float = float("nan")  # NaN with the period fixed
    misfit_per_chi2: float = float("nan")  # c of the module doc
    region68_fraction: float = float("nan")  # share of the sphere
    region95_fraction: float = float("nan")
    region95_max_sep_deg: float = float("nan")
    contrast: float = float("nan")  # median / best misfit of the grid
    noise_floor: float = float("nan")
    noise_ratio: float = float("nan")  # refined misfit / noise floor
    hac_lag: int = 0
    constrained: bool = False
    note: str = ""
    method: str = DEFAULT_METHOD  # the covariance's (axis_confidence)


def noise_floor(y: F64) -> float:
    """The misfit white noise alone would give (module doc) from measured curves (T, B)."""
    yn = np.asarray(y, dtype=float) / np.mean(y, axis=0)
    if yn.shape[0] < 3:
        return float("nan")
    d2 = yn[2:] - 2 * yn[1:-1] + yn[:-2]
    mad = np.median(np.abs(d2 - np.median(d2, axis=0)), axis=0)
    return float(np.mean((1.4826 * mad) ** 2 / 6.0))


def _bartlett_lag(g: F64) -> int:
    """Andrews' (1991) AR(1) plug-in lag of the Bartlett kernel for scores (T, K)."""
    n_t = g.shape[0]
    num = den = 0.0
    for k in range(g.shape[1]):
        x = g[:, k] - g[:, k].mean()
        v = float(np.sum(x * x))
        if n_t < 3 or v <= 0:
            continue
        rho = float(np.clip(np.sum(x[1:] * x[:-1]) / v, -0.97, 0.97))
        s4 = (v / n_t) ** 2
        num += 4 * rho**2 * s4 / ((1 - rho) ** 6 * (1 + rho) ** 2)
        den += s4 / (1 - rho) ** 4
    alpha = num / den if den > 0 else 0.0
    return int(np.clip(np.floor(1.1447 * (alpha * n_t) ** (1 / 3)), 0, max(0, n_t // 2)))


def sandwich_covariance(r: F64, jac: F64, n_t: int) -> tuple[F64, F64, int]:
    """``C = A^-1 S A^-1`` (K, K), ``A^-1`` and the lag, from residuals (M,) and their
    Jacobian (M, K) whose rows are epoch-major in blocks of ``M / n_t`` (module doc)."""
    k = jac.shape[1]
    g = (jac * r[:, None]).reshape(n_t, -1, k).sum(axis=1)  # per-epoch scores
    lag = _bartlett_lag(g)
    s = g.T @ g
    for ell in range(1, lag + 1):
        w = 1.0 - ell / (lag + 1.0)
        gamma = g[ell:].T @ g[:-ell]
        s += w * (gamma + gamma.T)
    a_inv = np.asarray(np.linalg.pinv(jac.T @ jac, rcond=1e-12), dtype=np.float64)
    return np.asarray(a_inv @ s @ a_inv, dtype=np.float64), a_inv, lag


def axis_confidence(
    bmap: ReflectivityMap,
    geo: EpochGeometry,
    y: F64,
    spin_body_axis: ArrayLike | None,
    refined: tuple[float, float, float, float],
    error: F64,
    dec_deg: F64,
    ra_deg: F64,
    free_period: bool = False,
    ranging: object | None = None,
    method: str = DEFAULT_METHOD,
) -> AxisConfidence:
    """Sigmas, regions and flags of the refined solution (module doc).

    Parameters
    ----------
    bmap
        The band map.
    geo
        Sun and observer directions and times of the epochs, with the refined period [s].
    y
        Measured band light curves (T, B).
    spin_body_axis
        The spin axis in the body frame (3,), or None (+z).
    refined
        RA, Dec, phase [deg] and misfit of the refined solution.
    error
        The grid's misfit surface (n_dec, n_ra).
    dec_deg, ra_deg
        The grid's cell centres [deg].
    free_period
        Whether the period was fitted (its sigma is then given).
    ranging
        The range-offset term (:class:`.spin_axis_ranging.RangingTerm`), or None.
    method
        The covariance (module doc): ``jackknife-warp`` (the default: covering
        ``jackknife-shrunk`` and ``sandwich-warp``), ``jackknife-shrunk`` (the sandwich plus
        :func:`shrunk_jackknife_spread`), ``sandwich-warp`` (the sandwich plus
        :func:`map_warp_covariance`), ``jackknife`` (the sandwich plus
        :func:`jackknife_covariance`), ``jackknife-map`` (that plus
        :func:`map_error_covariance`) or ``sandwich`` (:func:`sandwich_covariance`).
    """
    cov = a_inv = None
    lag, period_scale = 0, float("nan")
    if np.all(np.isfinite(refined[:3])):
        model = SpinMisfit.around(
            bmap, geo, y, spin_body_axis, refined[0], refined[1], free_period,
            ranging,  # type: ignore[arg-type]
        )  # fmt: skip
        x0 = np.array([0.0, 0.0, np.radians(refined[2])] + ([0.0] if free_period else []))
        got = _covariance(model, x0, ranging is not None, method)
        if got is not None:
            cov, a_inv, lag = got
        if free_period:
            step = np.array([0, 0, 0, 1e-6])
            period_scale = abs(model.period_s(x0 + step) - model.period_s(x0)) / 1e-6
    return confidence_from_covariance(
        cov, a_inv, error, dec_deg, ra_deg, refined, y, lag, period_scale, method
    )


def _covariance(
    model: SpinMisfit, x0: F64, ranged: bool, method: str
) -> tuple[F64, F64, int] | None:
    """(C, A^-1, lag) of ``method`` (:func:`axis_confidence`), or None where the model has
    no finite residuals or no gradient there."""
    r, jac = model.residuals(x0)
    if jac is None or not np.all(np.isfinite(r)) or not np.any(jac):
        return None
    cov, a_inv, lag = sandwich_covariance(r, jac, model.y.shape[0])
    if method == "jackknife-shrunk":
        cov = cov + shrunk_jackknife_spread(jackknife_refits(model, x0, ranged))[0]
    elif method == "sandwich-warp":
        cov = cov + map_warp_covariance(model, x0)
    elif method == "jackknife-warp":
        shrunk = shrunk_jackknife_spread(jackknife_refits(model, x0, ranged))[0]
        cov = covering_covariance(cov + shrunk, cov + map_warp_covariance(model, x0))
    elif method in ("jackknife", "jackknife-map"):  # plus the sandwich: never below the
        cov = cov + jackknife_covariance(model, x0, ranged)  # local curvature
    if method == "jackknife-map":
        cov = cov + map_error_covariance(model, x0)
    return cov, a_inv, lag


def confidence_from_covariance(
    cov: F64 | None,
    a_inv: F64 | None,
    error: F64,
    dec_deg: F64,
    ra_deg: F64,
    refined: tuple[float, float, float, float],
    y: F64,
    hac_lag: int = 0,
    period_scale: float = float("nan"),
    method: str = DEFAULT_METHOD,
) -> AxisConfidence:
    """Sigmas, regions and verdict from the parameters' covariance ``cov`` (K, K) and
    ``A^-1`` (K, K) (None: no sigmas; module doc), the grid's misfit surface ``error``
    (n_dec, n_ra) on cells ``dec_deg``, ``ra_deg`` [deg], the refined solution (RA, Dec,
    phase [deg], misfit), the measured curves ``y`` (T, B) and, with a free period, the
    period's change per unit of its parameter ``period_scale`` [s]."""
    out = AxisConfidence(hac_lag=hac_lag)
    finite = np.isfinite(error)
    e_min = float(np.min(error[finite])) if finite.any() else float("nan")
    out.contrast = float(np.median(error[finite]) / e_min) if e_min > 0 else float("nan")
    out.noise_floor = noise_floor(y)
    if np.isfinite(refined[3]) and out.noise_floor > 0:
        out.noise_ratio = float(refined[3] / out.noise_floor)
    if cov is not None and a_inv is not None:
        _sigmas(out, cov, a_inv, period_scale)
    _regions(out, error, dec_deg, ra_deg, refined)
    out.constrained, out.note = _verdict(out)
    return out


def _sigmas(out: AxisConfidence, cov: F64, a_inv: F64, period_scale: float) -> None:
    # x = (a, b): a tilts the axis towards -b_frame... (:mod:`.spin_axis_gradient`): the
    # tangent rotation (a, b) moves the axis by (b, -a) in the frame's (x, y); x is the
    # ascending node (east), y north of it
    c_ax = EAST_NORTH @ cov[:2, :2] @ EAST_NORTH.T
    a_ax = EAST_NORTH @ a_inv[:2, :2] @ EAST_NORTH.T
    var = np.diag(c_ax)
    if not np.all(np.isfinite(var)) or np.any(var <= 0):
        return
    deg = np.degrees(1.0)
    out.sigma_east_deg, out.sigma_north_deg = (float(np.sqrt(v)) * deg for v in var)
    out.correlation_east_north = float(c_ax[0, 1] / np.sqrt(var[0] * var[1]))
    out.sigma_axis_deg = float(np.sqrt(np.max(np.linalg.eigvalsh(c_ax)))) * deg
    out.sigma_phase_deg = float(np.sqrt(max(cov[2, 2], 0.0))) * deg
    if cov.shape[0] > 3 and np.isfinite(period_scale):
        out.sigma_period_s = float(np.sqrt(max(cov[3, 3], 0.0)) * period_scale)
    try:
        out.misfit_per_chi2 = float(np.trace(c_ax @ np.linalg.inv(a_ax)) / 2.0)
    except np.linalg.LinAlgError:
        out.misfit_per_chi2 = float("nan")


def _regions(
    out: AxisConfidence,
    error: F64,
    dec_deg: F64,
    ra_deg: F64,
    refined: tuple[float, float, float, float],
) -> None:
    c = out.misfit_per_chi2
    finite = np.isfinite(error)
    if not finite.any():
        return
    if not (np.isfinite(c) and c > 0):  # no curvature: the whole surface is the region
        dchi = np.where(finite, 0.0, np.inf)
    else:
        dchi = np.where(finite, (error - np.min(error[finite])) / c, np.inf)
    area = np.cos(np.radians(dec_deg))[:, None] * np.ones((1, ra_deg.size))
    total = float(np.sum(area))
    out.region68_fraction = float(np.sum(area[dchi <= DCHI2_68]) / total)
    in95 = dchi <= DCHI2_95
    out.region95_fraction = float(np.sum(area[in95]) / total)
    if np.all(np.isfinite(refined[:2])) and in95.any():
        dd, rr = np.meshgrid(dec_deg, ra_deg, indexing="ij")
        sep = angular_distance_deg(rr[in95], dd[in95], refined[0], refined[1])
        out.region95_max_sep_deg = float(np.max(sep))


def _verdict(out: AxisConfidence) -> tuple[bool, str]:
    """Whether the axis is constrained, and the note that says why not or how well."""
    notes = []
    flat = []
    if out.contrast < FLAT_CONTRAST:
        flat.append(f"the median misfit over the sphere is only {out.contrast:.3g} times the best")
    if out.region95_fraction > MAX_REGION_FRACTION:
        flat.append(f"the 95 % region covers {100 * out.region95_fraction:.3g} % of the sphere")
    if not out.sigma_axis_deg <= MAX_SIGMA_DEG:
        flat.append(f"the axis sigma is {out.sigma_axis_deg:.3g} deg")
    if flat:
        notes.append(f"{FLAT_NOTE}: " + "; ".join(flat))
    elif out.region95_max_sep_deg > SECOND_REGION_DEG:
        notes.append(
            "the 95 % region reaches "
            f"{out.region95_max_sep_deg:.3g} deg from the refined axis: a second minimum "
            "(the mirror?) is not excluded"
        )
    if out.noise_ratio > MAX_NOISE_RATIO:
        notes.append(
            f"the misfit is {out.noise_ratio:.3g} times the noise floor ({out.noise_floor:.3g}): "
            "the model does not fit the data (a wrong period or spin model, or a map error "
            "above the noise)"
        )
    constrained = not flat and not out.region95_max_sep_deg > SECOND_REGION_DEG
    if not notes:
        notes.append(
            f"axis sigma {out.sigma_axis_deg:.3g} deg (east {out.sigma_east_deg:.3g}, north "
            f"{out.sigma_north_deg:.3g}); 95 % region {100 * out.region95_fraction:.3g} % "
            "of the sphere"
        )
        if out.noise_ratio > MODEL_ERROR_RATIO:
            notes.append(_model_error_note(out))
        if np.isfinite(out.sigma_period_s):
            notes.append(FREE_PERIOD_NOTE)
    return constrained, "; ".join(notes)


def _model_error_note(out: AxisConfidence) -> str:
    """What a refined misfit above :data:`MODEL_ERROR_RATIO` times the noise means for the
    sigmas of ``out.method``."""
    head = (
        f"the misfit is {out.noise_ratio:.3g} times the noise floor: the map's (or the spin "
        "model's) own error dominates the residuals"
    )
    field = "the sigmas count the map's error as its directions displaced by a fraction of a pixel"
    if out.method == "jackknife-warp":
        return (
            f"{head}; {field}, sized from the residuals (error / sigma standard deviations "
            "0.76-1.29 on the calibration bench), not a wrong spin model (docs/spin-axis.md, "
            "Sigmas)"
        )
    if out.method == "sandwich-warp":
        return f"{head}; {field}, without the jackknife: they may be too small (docs/spin-axis.md)"
    return (
        f"{head}, and the sigmas count it only as far as the jackknife's refits see it: they "
        "may be too small (docs/spin-axis.md, Sigmas)"
    )


def with_period(geo: EpochGeometry, period_s: float) -> EpochGeometry:
    """``geo`` with another period [s]."""
    return dataclasses.replace(geo, period_s=float(period_s))
