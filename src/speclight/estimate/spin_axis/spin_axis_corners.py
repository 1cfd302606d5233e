"""Where each (axis, epoch) of the spin-axis grid pass reads the spin-frame table.

The lookup of :mod:`.spin_axis_lookup` (nearest polar and azimuth cell of the spin frame,
linear in phase angle and roll, the ``n_phases`` phases of one axis and epoch one contiguous
window of the grid) for a whole chunk of axes x all epochs in one vectorised call
(:func:`lookup_corners`): the phase vector, the Sun-observer plane and the phase-angle
weights once per epoch (:func:`epoch_frames`), then only rotated into each candidate's spin
frame. :mod:`.spin_axis_grid` sums what these corners read.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.spin_axis.spin_axis_lookup import EpochGeometry, SpinFrameMap
from speclight.maps.map_geometry import map_coordinates
from speclight.maps.map_lookup import phase_angle_weights

F64 = NDArray[np.float64]
F32 = NDArray[np.float32]
I64 = NDArray[np.int64]


@dataclass(frozen=True)
class Corners:
    """Window rows (for :func:`window_view`) and weights of the interpolation corners of
    ``A x T`` lookups (axis slowest): ``rows`` (A T, corners), ``weights`` (A T, corners)
    float32 or None for one corner of weight 1; ``bad`` (A T,) where the geometry has no
    phase vector."""

    rows: I64
    weights: F32 | None
    bad: NDArray[np.bool_]


@dataclass(frozen=True)
class EpochFrames:
    """What the lookups need of the epochs, in GCRS (:func:`epoch_frames`): the phase vector
    ``p`` (T, 3) (NaN rows where there is none), the unit vector ``u`` (T, 3) of the
    Sun-observer plane on the Sun's side (0 at phase angle 0), the spin turn since the first
    epoch [rad] (T,) and the phase-angle weights of the map."""

    p: F64
    u: F64
    spin_turn_rad: F64
    phase_weights: tuple


def epoch_frames(geo: EpochGeometry, phase_angle_deg: F64) -> EpochFrames:
    """:class:`EpochFrames` of ``geo`` for a map of the phase angles ``phase_angle_deg``.

    A rotation keeps lengths and angles, so the phase vector, the plane's unit vector and the
    phase angle are computed once per epoch in GCRS (as
    :func:`speclight.maps.map_geometry.map_coordinates` does in the body frame) and only
    turned into each candidate's spin frame.
    """
    p, a, _ = map_coordinates(geo.sun_gcrs, geo.observer_gcrs)
    with np.errstate(invalid="ignore", divide="ignore"):
        s = geo.sun_gcrs / np.linalg.norm(geo.sun_gcrs, axis=1)[:, None]
        o = geo.observer_gcrs / np.linalg.norm(geo.observer_gcrs, axis=1)[:, None]
        d = s - o
        nd = np.linalg.norm(d, axis=1)
        u = np.where((nd > 1e-12)[:, None], d / np.where(nd > 1e-12, nd, 1.0)[:, None], 0.0)
    a_deg = np.degrees(np.nan_to_num(a))
    spin_turn = 2 * np.pi * np.mod(geo.t_s / geo.period_s, 1.0)
    return EpochFrames(p, np.nan_to_num(u), spin_turn, phase_angle_weights(phase_angle_deg, a_deg))


def _roll(p: F64, u: F64) -> F64:
    """Roll [rad, 0..2 pi) of ``u`` about ``p`` (..., 3) in the spin frame (the convention of
    :mod:`speclight.maps.map_geometry`: ``e_lon = normalize(z x p)``, ``e_lat = p x e_lon``,
    ``e_lon = y`` within 1e-9 of the poles), from the components without normalising:
    ``rho (u . e_lon) = u_y p_x - u_x p_y``, ``rho (u . e_lat) = u_z rho^2 - p_z (u_x p_x +
    u_y p_y)`` with ``rho = |z x p|``."""
    px, py, pz = p[..., 0], p[..., 1], p[..., 2]
    ux, uy, uz = u[..., 0], u[..., 1], u[..., 2]
    rho2 = px * px + py * py
    lon_c = uy * px - ux * py
    lat_c = uz * rho2 - pz * (ux * px + uy * py)
    pole = rho2 < 1e-18
    if np.any(pole):
        lon_c = np.where(pole, uy, lon_c)
        lat_c = np.where(pole, uz * px - ux * pz, lat_c)
    return np.asarray(np.mod(np.arctan2(lat_c, lon_c), 2 * np.pi))


def lookup_corners(
    sfm: SpinFrameMap, ef: EpochFrames, frames: F64, spin_turn_rad: F64 | None = None
) -> Corners:
    """Corners of the lookups of ``frames`` (A, 3, 3) x the epochs of ``ef`` (phase ``k``:
    ``360 k / K`` deg at ``t_s = 0``; the grid layout of :class:`.SpinFrameMap`);
    ``spin_turn_rad`` (A, T): each axis's own spin turn (its own period), else ``ef``'s."""
    n_ax = frames.shape[0]
    p = np.matmul(ef.p[None], frames)  # (A, T, 3): frame^T p, the spin-frame phase vectors
    n_k, m = sfm.n_phases, sfm.m
    n_az = n_k * m
    turn = ef.spin_turn_rad if spin_turn_rad is None else spin_turn_rad
    az = np.nan_to_num(np.arctan2(p[..., 1], p[..., 0]) - turn)  # NaN: a bad lookup (below)
    c = np.rint(np.mod(az.ravel(), 2 * np.pi) / (2 * np.pi) * n_az).astype(np.int64) % n_az
    pz = p[..., 2].ravel()
    bad = ~np.isfinite(pz)
    polar = np.arccos(np.clip(np.nan_to_num(pz), -1.0, 1.0))
    i_polar = np.minimum((polar / np.pi * sfm.n_polar).astype(np.int64), sfm.n_polar - 1)
    q, s_sub = c // m, c % m
    n_p, n_r = sfm.phase_angle_deg.size, sfm.n_rolls
    base = (i_polar * m + s_sub) * n_p * n_r
    start = (n_k - 1 - q) % n_k  # element k of the window: azimuth cell q - k
    j_idx, w_j = ef.phase_weights
    if n_r > 1:
        roll = _roll(p, np.matmul(ef.u[None], frames)).ravel()
        f = np.nan_to_num(roll) / (2 * np.pi / n_r)
        r_lo = np.floor(f).astype(np.int64) % n_r
        w_r = f - np.floor(f)
    rows: list[I64] = []
    weights: list[F64] = []
    for jj in range(2 if n_p > 1 else 1):
        jt = np.tile(j_idx[jj], n_ax)
        wj = np.tile(w_j[jj], n_ax)
        for rr in range(2 if n_r > 1 else 1):
            r_idx = (r_lo + rr) % n_r if n_r > 1 else 0
            rows.append((base + jt * n_r + r_idx) * (2 * n_k) + start)
            weights.append(wj * (w_r if rr else 1.0 - w_r) if n_r > 1 else wj)
    # one corner: weight 1 (phase_angle_weights of one stored angle are ones)
    w = None if len(rows) == 1 else np.stack(weights, axis=1).astype(np.float32)
    return Corners(np.stack(rows, axis=1), w, bad)
