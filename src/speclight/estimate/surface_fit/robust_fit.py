"""Robust least squares in magnitudes, its uncertainties and their calibration check.

Plain arrays: a model ``magnitude(u) -> (R,)``, observed magnitudes and their sigmas.

* **Loss.** Real magnitudes have outliers (a star in the aperture, a wrong association), so
  the residuals ``(m_obs - m(u)) / s`` are minimised with the soft-L1 loss
  ``2 (sqrt(1 + z^2) - 1)`` (quadratic inside about ``F_SCALE`` s, linear beyond;
  ``scipy.optimize.least_squares(loss="soft_l1")``), where ``s^2 = sigma^2 + tau^2`` and
  ``tau`` the model's own scatter: the residuals' robust spread (1.4826 median absolute
  deviation) beyond the sigmas, re-estimated after each of :data:`SCATTER_ROUNDS` fits (the
  sigmas of real photometry are far below what a satellite model misses by).
* **Starts.** From the given start and from the middle of the bounds; the lower cost wins.
* **Jacobian covariance.** ``(J^T J)^-1 max(1, chi2 / dof)``, J the (loss-weighted)
  Jacobian at the solution (Gauss-Newton).
* **Bootstrap.** The rows resampled with replacement, refitted from the solution with the
  same ``tau``; the standard deviation of the refitted variables.
* **Calibration check.** Both are computed; where the bootstrap spread agrees with the
  Jacobian's standard deviation within a factor :data:`CALIBRATION_FACTOR`, the Jacobian's
  is reported (it is the exact local curvature), else the bootstrap's (the linearisation
  does not hold, or the residuals are not independent and alike).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

F64 = NDArray[np.float64]
I64 = NDArray[np.intp]
#: Residuals beyond this many s count linearly (soft L1).
F_SCALE = 2.0
#: Fits, each with the scatter tau of the previous one's residuals.
SCATTER_ROUNDS = 3
#: Bootstrap spread and Jacobian sigma agreeing within this factor: the Jacobian is used.
CALIBRATION_FACTOR = 1.5
#: Least ``s`` [mag] (a row without a sigma and a perfect model).
MIN_SIGMA_MAG = 1e-3


@dataclass
class RobustFit:
    """The solution ``u``, its cost and the residual scatter ``tau_mag`` [mag]."""

    u: F64
    cov: F64
    tau_mag: float
    chi2: float
    dof: int
    success: bool
    message: str


def _scale(sigma: F64, tau: float) -> F64:
    sig = np.where(np.isfinite(sigma), sigma, 0.0)
    return np.asarray(np.maximum(np.sqrt(sig**2 + tau**2), MIN_SIGMA_MAG))


def _solve(
    magnitude: Callable[[F64], F64],
    observed: F64,
    scale: F64,
    rows: I64,
    starts: list[F64],
    bounds: tuple[F64, F64],
) -> Any:
    def residual(u: F64) -> F64:
        return np.asarray((observed[rows] - magnitude(u)[rows]) / scale[rows])

    best = None
    for start in starts:
        x0 = np.clip(start, bounds[0] + 1e-9, bounds[1] - 1e-9)
        res = least_squares(
            residual, x0, bounds=bounds, loss="soft_l1", f_scale=F_SCALE, x_scale="jac",
            diff_step=1e-5, max_nfev=400,
        )  # fmt: skip
        if best is None or res.cost < best.cost:
            best = res
    assert best is not None
    return best


def robust_fit(
    magnitude: Callable[[F64], F64],
    observed: F64,
    sigma: F64,
    rows: I64,
    start: F64,
    bounds: tuple[F64, F64],
    tau_mag: float | None = None,
) -> RobustFit:
    """Fit ``u`` so that ``magnitude(u)[rows]`` matches ``observed[rows]`` (module doc).

    ``tau_mag`` given: that scatter, not re-estimated (one fit from ``start`` only).
    """
    lo, hi = bounds
    starts = [start] if tau_mag is not None else [start, 0.5 * (lo + hi)]
    rounds = 1 if tau_mag is not None else SCATTER_ROUNDS
    tau = 0.0 if tau_mag is None else tau_mag
    res = None
    for _ in range(rounds):
        res = _solve(magnitude, observed, _scale(sigma, tau), rows, starts, bounds)
        starts = [res.x]
        if tau_mag is None:
            r = observed[rows] - magnitude(res.x)[rows]
            mad = 1.4826 * float(np.median(np.abs(r - np.median(r))))
            sig2 = float(np.median(np.where(np.isfinite(sigma[rows]), sigma[rows], 0.0) ** 2))
            tau = float(np.sqrt(max(mad**2 - sig2, 0.0)))
    assert res is not None
    n, p = rows.size, res.x.size
    dof = max(n - p, 1)
    chi2 = 2.0 * float(res.cost)
    jac = np.asarray(res.jac)
    cov = covariance(jac) * max(1.0, chi2 / dof)
    return RobustFit(
        u=np.asarray(res.x, dtype=float),
        cov=cov,
        tau_mag=tau,
        chi2=chi2,
        dof=dof,
        success=bool(res.success),
        message=str(res.message),
    )


def covariance(jac: F64) -> F64:
    """``(J^T J)^-1`` (P, P), with an infinite variance for every variable that has a part
    in a direction the data do not see (an eigenvalue of ``J^T J`` below 1e-12 of the
    largest: e.g. the lobe of a surface never seen in its mirror direction)."""
    w, v = np.linalg.eigh(jac.T @ jac)
    null = w <= 1e-12 * max(float(w.max(initial=0.0)), 1e-300)
    inv = np.where(null, 0.0, 1.0 / np.where(null, 1.0, w))
    cov = (v * inv) @ v.T
    blind = np.any(np.abs(v[:, null]) > 1e-3, axis=1)
    cov[blind, :] = np.inf
    cov[:, blind] = np.inf
    return np.asarray(cov)


def bootstrap_std(
    magnitude: Callable[[F64], F64],
    observed: F64,
    sigma: F64,
    rows: I64,
    fit: RobustFit,
    bounds: tuple[F64, F64],
    n_draws: int,
    seed: int,
) -> F64:
    """Standard deviation (P,) of ``u`` refitted to ``n_draws`` resamplings of ``rows``."""
    rng = np.random.default_rng(seed)
    draws = np.empty((n_draws, fit.u.size))
    for b in range(n_draws):
        pick = rng.choice(rows, size=rows.size, replace=True)
        draws[b] = robust_fit(magnitude, observed, sigma, pick, fit.u, bounds, fit.tau_mag).u
    return np.asarray(draws.std(axis=0, ddof=1))


def calibrated_std(jacobian_std: F64, bootstrap: F64) -> tuple[F64, list[str]]:
    """Per variable: the Jacobian's std where the bootstrap agrees within
    :data:`CALIBRATION_FACTOR`, else the bootstrap's; and which was used."""
    ratio = bootstrap / np.maximum(jacobian_std, 1e-300)
    ok = (ratio <= CALIBRATION_FACTOR) & (ratio >= 1.0 / CALIBRATION_FACTOR)
    ok |= ~np.isfinite(jacobian_std)  # a direction the data do not see: no bootstrap helps
    return np.where(ok, jacobian_std, bootstrap), ["jacobian" if o else "bootstrap" for o in ok]


def night_halves(time_utc: NDArray[np.datetime64], longitude_deg: F64) -> tuple[I64, I64, str]:
    """Two halves of the rows by date: the local nights (the UTC date at local mean solar
    time minus 12 h) in order, the first half of the rows (the nights until it holds at least
    half) and the rest; where one night holds them all, the rows before and after the median
    time. Returns both halves and ``"night"`` or ``"time"``."""
    t_s = (time_utc - np.datetime64("1970-01-01T00:00:00")) / np.timedelta64(1, "s")
    local_s = t_s + np.asarray(longitude_deg) / 360.0 * 86400.0 - 43200.0
    night = np.floor(local_s / 86400.0).astype(np.int64)
    nights, counts = np.unique(night, return_counts=True)
    rows = np.arange(time_utc.size)
    if nights.size >= 2:
        cut = int(np.searchsorted(np.cumsum(counts), 0.5 * time_utc.size))
        cut = min(cut, nights.size - 2)
        first = np.isin(night, nights[: cut + 1])
        return rows[first], rows[~first], "night"
    order = np.argsort(t_s, kind="stable")
    half = time_utc.size // 2
    return np.sort(order[:half]), np.sort(order[half:]), "time"
