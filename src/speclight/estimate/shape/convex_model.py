"""Light curves of a convex polyhedron from its EGI, with analytic derivatives.

A convex body casts no shadow on itself and hides none of its own lit facets, so its
brightness is the sum over facets seen and lit (Kaasalainen & Torppa 2001, Icarus 153, 24,
eq. 1, doi:10.1006/icar.2001.6673):

``L(t) = sum_k a_k S(mu0_k, mu_k) [mu0_k > 0, mu_k > 0]``,

``mu0_k = n_k . s_body(t)``, ``mu_k = n_k . o_body(t)``. The body frame turns about its z axis,
the pole ``(lambda, beta)`` in ecliptic J2000, with the sidereal period ``P``; an ecliptic
vector ``v`` is in the body frame ``R_z(-phi) R_y(beta - 90 deg) R_z(-lambda) v`` with
``phi = phi0 + 2 pi (t - t0) / P`` (DAMIT's convention, Durech et al. 2010, A&A 513, A46).
``phi0`` is fixed at 0: a turn of the body about its pole is a turn of its EGI.

Parameters ``theta = (lambda [rad], beta [rad], P [h], g_1 .. g_K)`` with areas ``a = exp(g)``.
Residuals per point: calibrated ``(y - L) / sigma``; relative ``(y - ybar L / Lbar) /
sigma`` with the curve's means (data and model compared as ratios to their means).
Two penalties as extra rows (convexinv's regularisation): the EGI's closure
``w_closure sqrt(N) sum a n / sum a`` (3 rows) and, when every curve is relative (the scale
of the areas is then free), ``w_scale sqrt(N) mean(g)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.shape.inversion_data import InversionData
from speclight.estimate.shape.scattering import ScatteringLaw

F64 = NDArray[np.float64]
N_ROTATION = 3  # lambda, beta, period
HOURS_PER_DAY = 24.0
CLOSURE_WEIGHT = 0.1
SCALE_WEIGHT = 0.01
_KZ = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
_KY = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 0.0], [-1.0, 0.0, 0.0]])


def _rz(a: F64) -> F64:
    c, s = np.cos(a), np.sin(a)
    z, o = np.zeros_like(c), np.ones_like(c)
    return np.moveaxis(np.array([[c, -s, z], [s, c, z], [z, z, o]]), (0, 1), (-2, -1))


def _ry(a: float) -> F64:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def ecliptic_to_body(
    lambda_rad: float, beta_rad: float, period_h: float, t_d: F64, phi0_rad: float = 0.0
) -> F64:
    """(N, 3, 3) rotations from ecliptic J2000 to the body frame at ``t_d`` [d] after t0."""
    phi = phi0_rad + 2.0 * np.pi * HOURS_PER_DAY * t_d / period_h
    pole = _ry(beta_rad - np.pi / 2.0) @ _rz(np.array(-lambda_rad))
    return np.asarray(_rz(-phi) @ pole)


def _body_and_derivatives(
    v: F64, lambda_rad: float, beta_rad: float, period_h: float, t_d: F64
) -> tuple[F64, F64]:
    """Body-frame vectors (N, 3) and their derivatives (3, N, 3) by lambda, beta, P."""
    rz_lam = _rz(np.array(-lambda_rad))
    ry = _ry(beta_rad - np.pi / 2.0)
    w = v @ rz_lam.T  # R_z(-lambda) v
    u = w @ ry.T  # the pole frame
    omega = 2.0 * np.pi * HOURS_PER_DAY / period_h  # [rad/d]
    rphi = _rz(-omega * t_d)
    body = np.einsum("nij,nj->ni", rphi, u)
    d_lam = -np.einsum("nij,nj->ni", rphi, (w @ _KZ.T) @ ry.T)
    d_bet = np.einsum("nij,nj->ni", rphi, u @ _KY.T)
    # d phi / d P = -omega t / P, and d R_z(-phi) / d phi = -K_z R_z(-phi)
    d_per = -(body @ _KZ.T) * (-omega * t_d / period_h)[:, None]
    return body, np.stack([d_lam, d_bet, d_per])


@dataclass(frozen=True)
class ConvexModel:
    """The forward model of one data set (module doc).

    Attributes
    ----------
    data
        The light curves.
    normals
        (K, 3) facet normals.
    law
        The scattering law.
    t0_jd
        Epoch of ``phi = phi0`` [d].
    """

    data: InversionData
    normals: F64
    law: ScatteringLaw
    t0_jd: float

    @property
    def n_parameters(self) -> int:
        """``3 + K``."""
        return N_ROTATION + len(self.normals)

    def brightness(self, theta: F64, jacobian: bool = False) -> tuple[F64, F64 | None]:
        """``L`` (N,) and, with ``jacobian``, ``dL/dtheta`` (N, 3 + K)."""
        lam, bet, per = (float(x) for x in theta[:N_ROTATION])
        a = np.exp(theta[N_ROTATION:])
        t = self.data.time_jd - self.t0_jd
        s_b, ds = _body_and_derivatives(self.data.sun_ecliptic, lam, bet, per, t)
        o_b, do = _body_and_derivatives(self.data.observer_ecliptic, lam, bet, per, t)
        mu0, mu = s_b @ self.normals.T, o_b @ self.normals.T
        seen = (mu0 > 0) & (mu > 0)
        mu0c, muc = np.where(seen, mu0, 0.0), np.where(seen, mu, 0.0)
        s, s0, s1 = self.law(mu0c, muc, self.data.cos_half_phase[:, None])
        s = np.where(seen, s, 0.0)
        lum = s @ a
        if not jacobian:
            return lum, None
        s0, s1 = np.where(seen, s0, 0.0), np.where(seen, s1, 0.0)
        jac = np.empty((lum.size, self.n_parameters))
        for p in range(N_ROTATION):
            jac[:, p] = (s0 * (ds[p] @ self.normals.T) + s1 * (do[p] @ self.normals.T)) @ a
        jac[:, N_ROTATION:] = s * a[None, :]
        return lum, jac

    def residuals(self, theta: F64) -> tuple[F64, F64]:
        """Residuals (N + penalties,) and their Jacobian (module doc)."""
        d = self.data
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            return self._residuals(theta, d)

    def _residuals(self, theta: F64, d: InversionData) -> tuple[F64, F64]:
        lum, dlum = self.brightness(theta, jacobian=True)
        assert dlum is not None
        r, jac = _compare(d, lum, dlum)
        g = theta[N_ROTATION:]
        a = np.exp(g)
        total = np.sum(a)
        closure = a @ self.normals / total
        w = CLOSURE_WEIGHT * np.sqrt(d.n_points)
        rows_r = [w * closure]
        rows_j = np.zeros((3, self.n_parameters))
        rows_j[:, N_ROTATION:] = w * (self.normals.T * a - np.outer(closure, a)) / total
        rows = [rows_j]
        if not np.any(d.calibrated):
            ws = SCALE_WEIGHT * np.sqrt(d.n_points)
            rows_r.append(np.array([ws * np.mean(g)]))
            scale_row = np.zeros((1, self.n_parameters))
            scale_row[0, N_ROTATION:] = ws / g.size
            rows.append(scale_row)
        return np.concatenate([r, *rows_r]), np.vstack([jac, *rows])

    def fitted(self, theta: F64) -> F64:
        """The model on the data's scale: ``L`` for calibrated curves, ``ybar L / Lbar``
        for relative ones (N,)."""
        lum, _ = self.brightness(theta)
        scale = _relative_scale(self.data, lum)
        return np.asarray(lum * scale)

    def chi2(self, theta: F64) -> float:
        """Sum of the squared data residuals (penalties left out)."""
        lum, _ = self.brightness(theta)
        r = relative_residuals(self.data, lum)
        return float(r @ r)


def facet_brightness(
    sun_body: F64,
    observer_body: F64,
    normals: F64,
    areas: F64,
    law: ScatteringLaw,
    cos_half_phase: F64,
) -> F64:
    """``L`` (N,) of a convex EGI for body-frame unit vectors (N, 3) (module doc)."""
    mu0, mu = sun_body @ normals.T, observer_body @ normals.T
    seen = (mu0 > 0) & (mu > 0)
    s, _, _ = law(np.where(seen, mu0, 0.0), np.where(seen, mu, 0.0), cos_half_phase[:, None])
    return np.asarray(np.where(seen, s, 0.0) @ areas)


def relative_residuals(d: InversionData, lum: F64) -> F64:
    """Data residuals (N,) of a model brightness ``lum``: calibrated ``(y - L) / sigma``,
    relative ``(y - ybar L / Lbar) / sigma``."""
    with np.errstate(divide="ignore", invalid="ignore"):
        model = lum * _relative_scale(d, lum)
    return np.asarray(np.nan_to_num((d.brightness - model) / d.sigma, nan=1e6))


def _curve_means(d: InversionData, x: F64) -> F64:
    """Means over each point's light curve of the rows of ``x`` ((N,) or (N, P)), per point."""
    counts = np.bincount(d.curve, minlength=d.n_curves).astype(float)
    if x.ndim == 1:
        return np.asarray((np.bincount(d.curve, weights=x, minlength=d.n_curves) / counts)[d.curve])
    # points are sorted by time, curves by their first point: sum each run of a curve
    starts = np.flatnonzero(np.r_[True, d.curve[1:] != d.curve[:-1]])
    sums = np.add.reduceat(x, starts, axis=0) / counts[d.curve[starts], None]
    return np.asarray(np.repeat(sums, np.diff(np.r_[starts, d.curve.size]), axis=0))


def _relative_scale(d: InversionData, lum: F64) -> F64:
    """Per point ``ybar / Lbar`` on relative curves, 1 on calibrated ones."""
    rel = ~d.calibrated[d.curve]
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = _curve_means(d, d.brightness) / _curve_means(d, lum)
    return np.where(rel, ratio, 1.0)


def _compare(d: InversionData, lum: F64, dlum: F64) -> tuple[F64, F64]:
    rel = ~d.calibrated[d.curve]
    ybar, lbar = _curve_means(d, d.brightness), _curve_means(d, lum)
    safe = np.where(lbar > 0, lbar, 1.0)
    model = np.where(rel, ybar * lum / safe, lum)
    r = (d.brightness - model) / d.sigma
    dmean = _curve_means(d, dlum)
    drel = (ybar / safe)[:, None] * (dlum - (lum / safe)[:, None] * dmean)
    jac = -np.where(rel[:, None], drel, dlum) / d.sigma[:, None]
    return r, jac
