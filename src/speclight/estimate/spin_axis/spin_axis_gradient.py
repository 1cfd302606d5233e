"""The spin-axis misfit and its analytic derivatives with respect to the attitude parameters.

**Parameters** ``x = (a, b, phi, f)`` around a start axis whose spin reference frame at phase
0 is ``F0`` (body-to-GCRS, columns x, y, z; :func:`.spin_axis_lookup.axis_frames`):

* ``(a, b)`` [rad]: the rotation vector ``w = (a, b, 0)`` in ``F0``'s axes; the frame is
  ``F = F0 exp([w]x)``, its z column the candidate axis. This tilts the axis by ``|w|``
  towards ``F0``'s ``(-b, a)`` direction with no singularity at the celestial poles (the
  exponential map is smooth; its Jacobian is singular only at ``|w| = 2 pi``);
* ``phi`` [rad]: the rotation phase at ``t = 0`` measured in ``F`` (at ``w = 0`` the
  phase of the spin model, from the ascending node; :func:`to_spin_model` converts back);
* ``f`` [rad] (only with a free period): the extra rotation accumulated over the pass,
  ``2 pi t_span (1 / P - 1 / P0)`` with ``t_span = max |t|``: the spin frequency is
  ``1 / P0 + f / (2 pi t_span)``.

**Chain.** The body turns about the axis by ``theta(t) = phi + 2 pi t / P`` (spin model,
:func:`speclight.attitude.spin.spin_attitude`: body-to-GCRS ``F Rz(theta) M``, ``M`` the
turn of the spin body axis onto z), so an inertial direction ``g`` is, in the body frame,
``M^T Rz(-theta) exp(-[w]x) h`` with ``h = F0^T g`` fixed. Derivatives:
``d/dphi = M^T (v x z)``, ``d/df = (t / t_span) d/dphi`` (``v`` the spin-frame vector), and
``d exp(-[w]x) h / dw_k = g x [J_r(w)]_k`` (column ``k``) ``k`` (``g = exp(-[w]x) h``, ``J_r``
the right Jacobian of SO(3): ``I - (1 - cos t) / t^2 [w]x + (t - sin t) / t^3 [w]x^2``,
``t = |w|``). Then the map's interpolation and its derivative
(:func:`speclight.maps.map_lookup_grad.intensity_jacobian`), then the misfit of
:mod:`.spin_axis_core`: residuals ``r_tb = (p_tb / m_b - y_tb / mean y_b) / sqrt(T B)`` with
``m_b`` the mean of ``p_b`` over the epochs, ``dr = (dp / m - p dm / m^2) / sqrt(T B)``, and
with ranging returns the offsets' residuals ``sqrt(W / (n mean(o_meas^2))) (M / R - o_meas)``.
The misfit is ``sum r^2``; its gradient ``2 J^T r``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.attitude.quaternion import quat_to_matrix
from speclight.attitude.spin import body_axis_to_z
from speclight.estimate.spin_axis.spin_axis_lookup import EpochGeometry, axis_frames
from speclight.maps.map_lookup import ReflectivityMap
from speclight.maps.map_lookup_grad import intensity_jacobian

if TYPE_CHECKING:
    from speclight.estimate.spin_axis.spin_axis_ranging import RangingTerm

F64 = NDArray[np.float64]
Z = np.array([0.0, 0.0, 1.0])


def _skew(v: F64) -> F64:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def rotation_and_right_jacobian(w: F64) -> tuple[F64, F64]:
    """``exp([w]x)`` (3, 3) (Rodrigues) and the right Jacobian ``J_r(w)`` (3, 3) of SO(3)."""
    t = float(np.linalg.norm(w))
    k = _skew(w)
    k2 = k @ k
    if t < 1e-4:  # series of the coefficients, exact to ~t^4
        s, c1, c2 = 1.0 - t * t / 6, 0.5 - t * t / 24, 1.0 / 6 - t * t / 120
    else:
        s, c1, c2 = np.sin(t) / t, (1 - np.cos(t)) / t**2, (t - np.sin(t)) / t**3
    return np.eye(3) + s * k + c1 * k2, np.eye(3) - c1 * k + c2 * k2


@dataclass(frozen=True)
class SpinMisfit:
    """The misfit of :func:`.spin_axis_misfit.exact_misfit` as a function of ``x`` (module
    docstring) around the start frame ``frame0``."""

    bmap: ReflectivityMap
    geo: EpochGeometry
    y: F64  # (T, B) measured
    frame0: F64  # (3, 3) body-to-GCRS at phase 0 of the start axis
    spin_to_body: F64  # (3, 3) M^T
    t_span_s: float
    free_period: bool
    ranging: RangingTerm | None = None

    @classmethod
    def around(
        cls,
        bmap: ReflectivityMap,
        geo: EpochGeometry,
        y: F64,
        spin_body_axis: ArrayLike | None,
        ra_deg: float,
        dec_deg: float,
        free_period: bool = False,
        ranging: RangingTerm | None = None,
    ) -> SpinMisfit:
        """The misfit around the axis (RA, Dec) [deg]: ``x = (0, 0, radians(phase), 0)`` is
        the spin model's candidate (RA, Dec, phase) with the period ``geo.period_s``.

        Parameters
        ----------
        bmap
            The band map (:func:`.spin_axis_lookup.load_band_map`).
        geo
            Sun and observer directions and times of the epochs.
        y
            Measured band light curves (T, B).
        spin_body_axis
            The spin axis in the body frame (3,), or None (+z).
        ra_deg, dec_deg
            The axis the parameters are measured from [deg].
        free_period
            The period is a fourth parameter.
        ranging
            The range-offset term, or None.
        """
        m = body_axis_to_z(spin_body_axis)
        to_body = np.eye(3) if m is None else quat_to_matrix(m).T
        span = float(np.max(np.abs(geo.t_s))) if geo.t_s.size else 0.0
        return cls(
            bmap,
            geo,
            np.asarray(y, dtype=float),
            axis_frames(ra_deg, dec_deg)[0],
            to_body,
            span if span > 0 else 1.0,
            free_period,
            ranging,
        )

    @property
    def n_params(self) -> int:
        return 4 if self.free_period else 3

    def period_s(self, x: ArrayLike) -> float:
        """The period [s] of ``x``."""
        x = np.asarray(x, dtype=float)
        f = float(x[3]) if self.free_period else 0.0
        return 1.0 / (1.0 / self.geo.period_s + f / (2 * np.pi * self.t_span_s))

    def f_for_period(self, period_s: float) -> float:
        """The parameter ``f`` of a period [s]."""
        return 2 * np.pi * self.t_span_s * (1.0 / period_s - 1.0 / self.geo.period_s)

    def to_spin_model(self, x: ArrayLike) -> tuple[float, float, float, float]:
        """RA, Dec, phase [deg] of the spin model (from the ascending node) and the period
        [s] of ``x``."""
        x = np.asarray(x, dtype=float)
        rot, _ = rotation_and_right_jacobian(np.array([x[0], x[1], 0.0]))
        frame = self.frame0 @ rot
        z = frame[:, 2]
        ra = float(np.degrees(np.arctan2(z[1], z[0])) % 360.0)
        dec = float(np.degrees(np.arcsin(np.clip(z[2], -1.0, 1.0))))
        node = axis_frames(ra, dec)[0]
        delta = np.arctan2(frame[:, 0] @ node[:, 1], frame[:, 0] @ node[:, 0])
        phase = float(np.degrees(x[2] + delta) % 360.0)
        return ra, dec, phase, self.period_s(x)

    def _directions(self, x: F64, inertial: F64) -> tuple[F64, F64]:
        """Body-frame unit vectors (T, 3) of the inertial ``inertial`` (T, 3) and their
        derivatives (T, 3, K) with respect to ``x``."""
        rot, jr = rotation_and_right_jacobian(np.array([x[0], x[1], 0.0]))
        t = self.geo.t_s
        g = (inertial @ self.frame0) @ rot  # exp(-[w]x) h = rot^T h, as rows
        dg = np.stack([np.cross(g, jr[:, k]) for k in range(2)], axis=-1)  # (T, 3, 2)
        theta = x[2] + 2 * np.pi * np.mod(t / self.geo.period_s, 1.0)
        if self.free_period:
            theta = theta + x[3] * t / self.t_span_s
        c, s = np.cos(theta), np.sin(theta)

        def rz_minus(v: F64) -> F64:  # Rz(-theta) v, rows
            return np.stack([c * v[:, 0] + s * v[:, 1], -s * v[:, 0] + c * v[:, 1], v[:, 2]], -1)

        v = rz_minus(g)
        cols = [rz_minus(dg[:, :, 0]), rz_minus(dg[:, :, 1]), np.cross(v, Z)]
        if self.free_period:
            cols.append(np.cross(v, Z) * (t / self.t_span_s)[:, None])
        dv = np.stack(cols, axis=-1)
        return v @ self.spin_to_body.T, np.einsum("ij,tjk->tik", self.spin_to_body, dv)

    def body_directions(self, x: ArrayLike) -> tuple[F64, F64]:
        """Body-frame Sun and observer unit vectors (T, 3) of the epochs under ``x``."""
        x = np.asarray(x, dtype=float)
        return self._directions(x, self.geo.sun_gcrs)[0], self._directions(
            x, self.geo.observer_gcrs
        )[0]

    def residuals(self, x: ArrayLike, jacobian: bool = True) -> tuple[F64, F64 | None]:
        """Residuals (M,) whose sum of squares is the misfit, and their Jacobian (M, K)
        (None unless ``jacobian``); all infinite where the map gives no value or a band's
        predicted mean is not > 0 (as :func:`.spin_axis_misfit.exact_misfit`)."""
        x = np.asarray(x, dtype=float)
        sun, d_sun = self._directions(x, self.geo.sun_gcrs)
        obs, d_obs = self._directions(x, self.geo.observer_gcrs)
        if jacobian:
            p, dp = intensity_jacobian(self.bmap, sun, obs, d_sun, d_obs)
        else:  # the map's own lookup, without the derivatives' cost
            p, dp = self.bmap.intensity_1au(sun, obs), np.zeros(0)
        n_t, n_b = self.y.shape
        yn = self.y / np.mean(self.y, axis=0)
        m = np.mean(p, axis=0)
        if not (np.all(np.isfinite(p)) and np.all(m > 0)):
            n = n_t * n_b + (0 if self.ranging is None else self.ranging.offset_m.size)
            return np.full(n, np.inf), (np.zeros((n, self.n_params)) if jacobian else None)
        scale = 1.0 / np.sqrt(n_t * n_b)
        r = ((p / m - yn) * scale).ravel()
        jac = None
        if jacobian:
            dm = np.mean(dp, axis=0)
            jac = ((dp / m[:, None] - p[:, :, None] * dm[None] / (m**2)[:, None]) * scale).reshape(
                n_t * n_b, -1
            )
        rg = self.ranging
        if rg is not None and rg.weight:
            r_r, j_r = _ranging_residuals(rg, obs, d_obs, jacobian)
            r = np.concatenate([r, r_r])
            if jac is not None and j_r is not None:
                jac = np.concatenate([jac, j_r])
        return r, jac

    def misfit(self, x: ArrayLike) -> float:
        """The misfit ``sum r^2`` of ``x``."""
        r, _ = self.residuals(x, jacobian=False)
        return float(np.sum(r**2))

    def misfit_and_gradient(self, x: ArrayLike) -> tuple[float, F64]:
        """The misfit and its gradient ``2 J^T r`` (K,)."""
        r, jac = self.residuals(x)
        assert jac is not None
        e = float(np.sum(r**2))
        if not np.isfinite(e):
            return float("inf"), np.zeros(self.n_params)
        return e, 2.0 * jac.T @ r


def _ranging_residuals(
    rg: RangingTerm, obs: F64, d_obs: F64, jacobian: bool
) -> tuple[F64, F64 | None]:
    """Residuals ``sqrt(W / (n mean(o_meas^2))) (M / R - o_meas)`` (T B,) of the range
    offsets (0 where unmeasured) and their Jacobian (T B, K)."""
    if jacobian:
        rm, drm = intensity_jacobian(rg.bmap, obs, obs, d_obs, d_obs)
    else:
        rm, drm = rg.bmap.intensity_1au(obs, obs), np.zeros((obs.shape[0], 1, 1))
    n_b = rg.n_bands
    rm, drm = np.nan_to_num(rm), np.nan_to_num(drm)
    rate, mom = rm[:, :n_b], rm[:, n_b:]
    meas = rg.offset_m
    ok = np.isfinite(meas)
    norm = float(np.mean(meas[ok] ** 2)) if ok.any() else 0.0
    if norm <= 0:
        return np.zeros(meas.size), (np.zeros((meas.size, d_obs.shape[2])) if jacobian else None)
    c = np.sqrt(float(rg.weight or 0.0) / (ok.sum() * norm))
    pos = rate > 0
    safe = np.where(pos, rate, 1.0)
    off = np.where(pos, mom / safe, 0.0)
    r = np.where(ok, off - np.nan_to_num(meas), 0.0) * c
    if not jacobian:
        return r.ravel(), None
    d_off = (drm[:, n_b:] * safe[:, :, None] - mom[:, :, None] * drm[:, :n_b]) / (safe**2)[
        ..., None
    ]
    d_off = np.where((pos & ok)[:, :, None], d_off, 0.0) * c
    return r.ravel(), d_off.reshape(meas.size, -1)
