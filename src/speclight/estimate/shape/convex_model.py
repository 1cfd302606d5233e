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

from collections.abc import Callable
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


def _spin(u: F64, cos_phi: F64, sin_phi: F64) -> F64:
    """``R_z(-phi) u`` for (N, 3) vectors ``u`` and per-row ``cos, sin`` of ``phi``."""
    return np.stack(
        [cos_phi * u[:, 0] + sin_phi * u[:, 1], cos_phi * u[:, 1] - sin_phi * u[:, 0], u[:, 2]],
        axis=1,
    )


def _body_and_derivatives(
    v: F64, lambda_rad: float, beta_rad: float, period_h: float, t_d: F64
) -> tuple[F64, F64]:
    """Body-frame vectors (N, 3) and their derivatives (3, N, 3) by lambda, beta, P."""
    rz_lam = _rz(np.array(-lambda_rad))
    ry = _ry(beta_rad - np.pi / 2.0)
    w = v @ rz_lam.T  # R_z(-lambda) v
    omega = 2.0 * np.pi * HOURS_PER_DAY / period_h  # [rad/d]
    phi = omega * t_d
    c, s = np.cos(phi), np.sin(phi)
    body = _spin(w @ ry.T, c, s)
    d_lam = -_spin((w @ _KZ.T) @ ry.T, c, s)
    d_bet = _spin(w @ (_KY @ ry).T, c, s)  # d R_y(b) / db = K_y R_y(b)
    # d phi / d P = -omega t / P, and d R_z(-phi) / d phi = -K_z R_z(-phi)
    d_per = (body @ _KZ.T) * (omega * t_d / period_h)[:, None]
    return body, np.stack([d_lam, d_bet, d_per])


@dataclass(frozen=True)
class _Forward:
    """The brightness ``lum`` (N,) at a parameter vector with what its Jacobian needs: the
    areas ``a``, the facets' law values ``s``, ``s0 = dS/dmu0``, ``s1 = dS/dmu`` (N, K) and the
    body-frame Sun and observer vectors' derivatives ``ds``, ``do`` (3, N, 3)."""

    lum: F64
    a: F64
    normals: F64
    s: F64
    s0: F64
    s1: F64
    ds: F64
    do: F64

    def jacobian_into(self, jac: F64) -> None:
        """``dL/dtheta`` into ``jac`` (N, 3 + K). The rotation columns use ``sum_k a_k S'_k
        (n_k . dv) = dv . sum_k a_k S'_k n_k``: an (N, K) x (K, 3) product instead of an
        (N, K) array per parameter."""
        weighted = self.a[:, None] * self.normals
        g0, g1 = self.s0 @ weighted, self.s1 @ weighted
        for p in range(N_ROTATION):
            jac[:, p] = np.einsum("ij,ij->i", self.ds[p], g0) + np.einsum(
                "ij,ij->i", self.do[p], g1
            )
        np.multiply(self.s, self.a, out=jac[:, N_ROTATION:])


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
        state = self._forward(theta)
        if not jacobian:
            return state.lum, None
        jac = np.empty((self.data.n_points, self.n_parameters))
        state.jacobian_into(jac)
        return state.lum, jac

    def _forward(self, theta: F64) -> _Forward:
        """The brightness at ``theta`` and what its Jacobian needs.

        The (N, K) arrays are the cost here, so few are made: the cosines of facets not
        both lit and seen are set to 0, where every law has ``S = dS/dmu0 = dS/dmu = 0``."""
        lam, bet, per = (float(x) for x in theta[:N_ROTATION])
        a = np.exp(theta[N_ROTATION:])
        t = self.data.time_jd - self.t0_jd
        s_b, ds = _body_and_derivatives(self.data.sun_ecliptic, lam, bet, per, t)
        o_b, do = _body_and_derivatives(self.data.observer_ecliptic, lam, bet, per, t)
        mu0, mu = s_b @ self.normals.T, o_b @ self.normals.T
        seen = mu0 > 0
        seen &= mu > 0
        mu0 *= seen
        mu *= seen
        s, s0, s1 = self.law(mu0, mu, self.data.cos_half_phase[:, None])
        return _Forward(np.asarray(s @ a), a, self.normals, s, s0, s1, ds, do)

    def evaluate(self, theta: F64) -> tuple[F64, Callable[[], F64]]:
        """Residuals (N + penalties,) now and a function returning their Jacobian (module
        doc); the Jacobian costs about as much again, so a trial step that is not taken
        skips it (:func:`.lm_solver.levenberg_marquardt`)."""
        d = self.data
        n = d.n_points
        relative_only = not np.any(d.calibrated)
        rows = n + 3 + (1 if relative_only else 0)
        g = theta[N_ROTATION:]
        a = np.exp(g)
        total = np.sum(a)
        closure = a @ self.normals / total
        w = CLOSURE_WEIGHT * np.sqrt(n)
        ws = SCALE_WEIGHT * np.sqrt(n)
        r = np.empty(rows)
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            state = self._forward(theta)
            rel, ybar, safe = _relative_terms(d, state.lum)
            r[:n] = (d.brightness - np.where(rel, ybar * state.lum / safe, state.lum)) / d.sigma
        r[n : n + 3] = w * closure
        if relative_only:
            r[n + 3] = ws * np.mean(g)

        def jacobian() -> F64:
            jac = np.empty((rows, self.n_parameters))
            with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
                state.jacobian_into(jac[:n])
                _relative_jacobian(d, state.lum, rel, ybar, safe, jac[:n])
            jac[n:, :N_ROTATION] = 0.0
            jac[n : n + 3, N_ROTATION:] = w * (self.normals.T * a - np.outer(closure, a)) / total
            if relative_only:
                jac[n + 3, N_ROTATION:] = ws / g.size
            return jac

        return r, jacobian

    def residuals(self, theta: F64) -> tuple[F64, F64]:
        """Residuals (N + penalties,) and their Jacobian (module doc)."""
        r, jacobian = self.evaluate(theta)
        return r, jacobian()

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


def _relative_terms(d: InversionData, lum: F64) -> tuple[NDArray[np.bool_], F64, F64]:
    """Per point: relative curve or not, the curve's mean data ``ybar`` and mean model
    ``Lbar`` (1 where it is not > 0)."""
    lbar = _curve_means(d, lum)
    return ~d.calibrated[d.curve], _curve_means(d, d.brightness), np.where(lbar > 0, lbar, 1.0)


def _relative_jacobian(
    d: InversionData, lum: F64, rel: NDArray[np.bool_], ybar: F64, lbar: F64, jac: F64
) -> None:
    """The data residuals' Jacobian from ``jac`` = dL/dtheta (N, P), in place: relative rows
    ``(y - ybar L / Lbar) / sigma`` have ``-(ybar / Lbar) (dL - (L / Lbar) mean(dL)) / sigma``
    (means over the point's curve), calibrated rows ``(y - L) / sigma`` have ``-dL / sigma``."""
    if np.any(rel):
        shift = _curve_means(d, jac)
        shift *= np.where(rel, lum / lbar, 0.0)[:, None]
        jac -= shift
    jac *= (-np.where(rel, ybar / lbar, 1.0) / d.sigma)[:, None]
