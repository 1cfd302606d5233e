"""One convex fit: the Levenberg-Marquardt run of :mod:`.convex_model` from a start.

The start shape is a sphere (equal areas), scaled so that its mean brightness matches the
calibrated data's; from there LM moves the areas and the free rotation parameters
(Kaasalainen, Torppa & Muinonen 2001, Icarus 153, 37, sec. 2.3: the sphere start is as
good as any, the shape converges from it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.shape.convex_model import N_ROTATION, ConvexModel
from speclight.estimate.shape.lm_solver import LmResult, levenberg_marquardt

F64 = NDArray[np.float64]
#: Steps of one fit (convexinv's default stop is 50 iterations or a relative chi-square
#: change below 1e-3; most fits here stop by the change).
MAX_ITERATIONS = 50
RTOL = 1e-4


@dataclass(frozen=True)
class ConvexSolution:
    """A converged fit.

    Attributes
    ----------
    theta
        ``(lambda [rad], beta [rad], P [h], g_1 .. g_K)``.
    chi2
        Sum of squared data residuals.
    lm
        The solver's end state (residuals and Jacobian there).
    """

    theta: F64
    chi2: float
    lm: LmResult

    @property
    def lambda_deg(self) -> float:
        """Pole longitude, ecliptic J2000, in [0, 360) [deg]."""
        return float(np.rad2deg(self.theta[0]) % 360.0)

    @property
    def beta_deg(self) -> float:
        """Pole latitude, ecliptic J2000 [deg] (wrapped into [-90, 90])."""
        return float(np.rad2deg(np.arcsin(np.sin(self.theta[1]))))

    @property
    def period_h(self) -> float:
        """Sidereal period [h]."""
        return float(self.theta[2])

    @property
    def areas(self) -> F64:
        """(K,) facet areas ``exp(g)``."""
        return np.asarray(np.exp(self.theta[N_ROTATION:]))


def sphere_start(model: ConvexModel) -> F64:
    """Log-areas of a sphere whose mean brightness matches the calibrated data (0 for
    relative data)."""
    k = len(model.normals)
    d = model.data
    if not np.any(d.calibrated):
        return np.zeros(k)
    theta = np.concatenate([[0.0, np.pi / 2, 1.0], np.zeros(k)])
    lum, _ = model.brightness(theta)
    cal = d.calibrated[d.curve]
    scale = np.sum(d.brightness[cal]) / max(float(np.sum(lum[cal])), 1e-300)
    return np.full(k, np.log(max(scale, 1e-300)))


def fit_convex(
    model: ConvexModel,
    lambda_deg: float,
    beta_deg: float,
    period_h: float,
    *,
    log_areas: F64 | None = None,
    free_pole: bool = True,
    free_period: bool = True,
    max_iterations: int = MAX_ITERATIONS,
) -> ConvexSolution:
    """Fit areas (always) and the pole and period (where free) from a start (module doc)."""
    g0 = sphere_start(model) if log_areas is None else np.asarray(log_areas, float)
    theta0 = np.concatenate([[np.deg2rad(lambda_deg), np.deg2rad(beta_deg), period_h], g0])
    free = np.ones(theta0.size, bool)
    free[:2] = free_pole
    free[2] = free_period
    lm = levenberg_marquardt(model.evaluate, theta0, free, max_iterations=max_iterations, rtol=RTOL)
    return ConvexSolution(lm.x, model.chi2(lm.x), lm)


def fibonacci_poles(n: int) -> F64:
    """(n, 2) poles ``(lambda, beta)`` [deg] spread evenly over the sphere (a Fibonacci
    lattice: Gonzalez 2010, Math. Geosci. 42, 49, doi:10.1007/s11004-009-9257-x)."""
    k = np.arange(n) + 0.5
    beta = np.rad2deg(np.arcsin(1.0 - 2.0 * k / n))
    lam = (k * 360.0 * (1.0 - 1.0 / ((1 + np.sqrt(5.0)) / 2.0))) % 360.0
    return np.stack([lam, beta], axis=1)
