"""The fast grid pass (:mod:`speclight.estimate.spin_axis.spin_axis_grid`) against a straightforward
float64 computation, one candidate at a time, on tiny grids.

The reference does not share the fast path's machinery: each candidate's attitude comes from
the spin model (:func:`speclight.attitude.spin.spin_attitude`, quaternions), each epoch's
phase vector, phase angle and roll from :func:`speclight.maps.map_geometry.map_coordinates`
in the spin frame, the cell from the layout documented on
:class:`speclight.estimate.spin_axis.spin_axis_lookup.SpinFrameMap` (nearest polar and azimuth cell,
linear in phase angle and roll), and the misfit from its definition (mean over epochs and
bands of the squared difference of the light curves each divided by its mean; the ranging
term: the squared offset differences over the measured epochs and bands divided by their
number and the mean square of the measured offsets; docs/spin-axis.md), all in float64.

Tolerance: both read the same float32 table; the fast path multiplies and sums in float32.
A float32 sum of ``n`` products is within ``n eps32 sum|terms|`` of the exact one (Higham,
*Accuracy and Stability of Numerical Algorithms*, 2nd ed., section 4.2, first-order bound),
so the misfit, a mean of ``T B`` squared differences expanded into ``sum pn^2 - 2 sum pn yn
+ sum yn^2`` (all of size ~1 per epoch and band), is within ``~4 T eps32`` absolute of the
float64 one; we allow ``8 T eps32`` (2e-5 for 40 epochs) plus 1e-6 relative.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from speclight.attitude.quaternion import quat_to_matrix
from speclight.attitude.spin import spin_attitude
from speclight.estimate.spin_axis.spin_axis_core import radec_grid
from speclight.estimate.spin_axis.spin_axis_grid import grid_pass
from speclight.estimate.spin_axis.spin_axis_lookup import (
    EpochGeometry,
    SpinFrameMap,
    spin_frame_map,
)
from speclight.estimate.spin_axis.spin_axis_ranging import RangingTerm
from speclight.estimate.spin_axis.spin_axis_window_sums import compiled_available
from speclight.maps.map_geometry import healpix_directions, map_coordinates
from speclight.maps.map_lookup import MapHeader, ReflectivityMap, phase_angle_weights

EPS32 = float(np.finfo(np.float32).eps)
#: the two ways of summing over the epochs: numpy blocks, the compiled loop (numba)
WAYS = [
    pytest.param(False, id="numpy"),
    pytest.param(
        True,
        id="compiled",
        marks=pytest.mark.skipif(not compiled_available(), reason="numba is not installed"),
    ),
]
N_T, N_PHASES, GRID_DEG, PERIOD_S = 40, 12, 45.0, 47.0
BODY_AXIS = np.array([0.0, 1.0, 0.0])  # the spin about body y: spin frame != body frame


def _map(nside: int, angles_deg: list[float], n_rolls: int, n_ch: int) -> ReflectivityMap:
    """Smooth positive channels of direction, phase angle and roll (no render needed)."""
    d = healpix_directions(nside)
    a = np.radians(np.asarray(angles_deg))[None, :, None, None]
    r = (2 * np.pi * np.arange(n_rolls) / n_rolls)[None, None, :, None]
    lobes = np.array([[0.6, -0.48, 0.64], [0.0, 0.8, 0.6], [-0.6, 0.0, 0.8], [0.0, 0.0, 1.0]])
    dl = (d @ lobes[:n_ch].T)[:, None, None, :]
    b = np.arange(n_ch)[None, None, None, :]
    v = 1.5 + dl + 0.6 * dl**2 * np.cos(a) + 0.3 * np.sin(r + b) * np.sin(a) * d[:, :1, None, None]
    header = MapHeader(
        Path("synthetic"),
        nside,
        np.array([500.0]),
        [f"b{i}" for i in range(n_ch)],
        np.asarray(angles_deg, dtype=float),
        np.arange(n_rolls) * 360.0 / n_rolls,
        {},
    )
    return ReflectivityMap(header, d, v.astype(np.float32))


def _geometry(rng: np.random.Generator) -> EpochGeometry:
    """A fixed Sun and an observer sweeping 80 deg: phase angles 35-75 deg."""
    sun = np.array([1.0, 0.0, 0.0])
    ang = np.radians(np.linspace(35.0, 75.0, N_T))
    tilt = np.radians(20.0)
    obs = np.stack([np.cos(ang), np.sin(ang) * np.cos(tilt), np.sin(ang) * np.sin(tilt)], -1)
    t = np.sort(rng.uniform(0.0, 3 * PERIOD_S, N_T))
    return EpochGeometry(np.tile(sun, (N_T, 1)), obs, t, PERIOD_S)


def _lookup(sfm: SpinFrameMap, sun_body: np.ndarray, obs_body: np.ndarray) -> np.ndarray:
    """Channels (T, C) of one candidate, float64, from the layout of SpinFrameMap."""
    k, m = sfm.n_phases, sfm.m
    s = sun_body @ sfm.spin_to_body  # spin-frame vectors (body = spin_to_body @ spin)
    o = obs_body @ sfm.spin_to_body
    p, a, roll = map_coordinates(s, o)
    polar = np.arccos(np.clip(p[:, 2], -1.0, 1.0))
    i = np.minimum(np.floor(polar / np.pi * sfm.n_polar).astype(int), sfm.n_polar - 1)
    az = np.mod(np.arctan2(p[:, 1], p[:, 0]), 2 * np.pi)
    c = np.rint(az / (2 * np.pi) * k * m).astype(int) % (k * m)
    q, sub = c // m, c % m
    j, wj = phase_angle_weights(sfm.phase_angle_deg, np.degrees(a))
    f = roll / (2 * np.pi / sfm.n_rolls)
    r0 = np.floor(f).astype(int) % sfm.n_rolls
    wr = f - np.floor(f)
    out = np.zeros((len(p), sfm.values.shape[-1]))
    for jj in range(2):
        for rr, w_roll in ((0, 1.0 - wr), (1, wr)):
            r_idx = (r0 + rr) % sfm.n_rolls
            cell = sfm.values[i, sub, j[jj], r_idx, 2 * k - 1 - q].astype(float)
            out += (wj[jj] * w_roll)[:, None] * cell
    return out


def _body(geo: EpochGeometry, ra: float, dec: float, phase: float, coaxial: bool):
    rot = quat_to_matrix(spin_attitude(geo.t_s, ra, dec, PERIOD_S, phase, BODY_AXIS))
    o = np.einsum("tji,tj->ti", rot, geo.observer_gcrs)
    s = o if coaxial else np.einsum("tji,tj->ti", rot, geo.sun_gcrs)
    return s, o


def _misfit(p: np.ndarray, y: np.ndarray) -> float:
    pm = p.mean(axis=0)
    if np.any(pm <= 0):
        return np.inf
    return float(np.mean((p / pm - y / y.mean(axis=0)) ** 2))


def _ranging(rm: np.ndarray, scale: np.ndarray, meas: np.ndarray) -> float:
    n_b = meas.shape[1]
    r, mom = rm[:, :n_b] * scale[:n_b], rm[:, n_b:] * scale[n_b:]
    off = np.where(r > 0, mom / np.where(r > 0, r, 1.0), 0.0)
    ok = np.isfinite(meas)
    return float(np.sum((off - meas)[ok] ** 2) / (ok.sum() * np.mean(meas[ok] ** 2)))


def _candidates():
    ra, dec = radec_grid(GRID_DEG)
    dd, rr = np.meshgrid(dec, ra, indexing="ij")
    return rr.ravel(), dd.ravel(), np.arange(N_PHASES) * 360.0 / N_PHASES


def _check(fast: np.ndarray, ref: np.ndarray) -> None:
    assert np.array_equal(np.isfinite(fast), np.isfinite(ref))
    ok = np.isfinite(ref)
    np.testing.assert_allclose(fast[ok], ref[ok], rtol=1e-6, atol=8 * N_T * EPS32)
    # the same best phase for every axis wherever the best two are not within the tolerance
    srt = np.sort(ref, axis=1)
    clear = srt[:, 1] - srt[:, 0] > 2 * (8 * N_T * EPS32 + 1e-6 * srt[:, 1])
    assert clear.mean() > 0.9
    np.testing.assert_array_equal(np.argmin(fast, 1)[clear], np.argmin(ref, 1)[clear])


@pytest.mark.parametrize("compiled", WAYS)
def test_passive_map_four_corner_lookups_match_the_reference(compiled: bool) -> None:
    rng = np.random.default_rng(11)
    geo = _geometry(rng)
    bmap = _map(4, [20.0, 50.0, 90.0], 4, 3)
    sfm = spin_frame_map(bmap, BODY_AXIS, N_PHASES)
    ra, dec, phases = _candidates()
    truth = (45.0, 22.5, 90.0)  # a grid cell and phase
    y = _lookup(sfm, *_body(geo, *truth, coaxial=False)) * sfm.scale
    y *= 1 + 0.03 * rng.standard_normal(y.shape)
    ref = np.array(
        [
            [_misfit(_lookup(sfm, *_body(geo, a, d, ph, coaxial=False)), y) for ph in phases]
            for a, d in zip(ra, dec, strict=True)
        ]
    )
    for workers, block in ((1, 1024**2), (2, 1)):  # neither changes the result
        fast, e_r = grid_pass(
            sfm, geo, y, ra, dec, 7, None, None, block, workers, compiled=compiled
        )
        assert e_r is None
        _check(fast, ref)
    i = int(np.argmin(fast.min(axis=1)))
    assert (ra[i], dec[i], phases[np.argmin(fast[i])]) == truth


@pytest.mark.parametrize("compiled", WAYS)
@pytest.mark.parametrize("shares", [True, False])
def test_ranging_term_matches_the_reference(shares: bool, compiled: bool) -> None:
    rng = np.random.default_rng(12)
    geo = _geometry(rng)
    n_b = 2
    lmap = _map(4, [0.0], 1, 2 * n_b)  # channels [R0, R1, M0, M1], one geometry
    rsfm = spin_frame_map(lmap, BODY_AXIS, N_PHASES)
    assert rsfm.scale is not None
    ra, dec, phases = _candidates()
    if shares:  # laser light: the intensity is the R channels, lit from the observer
        geo = EpochGeometry(geo.observer_gcrs, geo.observer_gcrs, geo.t_s, geo.period_s)
        sub = ReflectivityMap(lmap.header, lmap.direction_body, lmap.intensity_W_sr_nm[..., :n_b])
    else:
        sub = _map(4, [20.0, 50.0, 90.0], 4, n_b)
    sfm = spin_frame_map(sub, BODY_AXIS, N_PHASES)
    truth = (225.0, -22.5, 300.0)
    y = _lookup(sfm, *_body(geo, *truth, coaxial=shares)) * sfm.scale
    meas = rng.normal(-0.4, 0.2, (N_T, n_b))
    meas[5, 1] = np.nan  # an unmeasured epoch and band weighs 0
    term = RangingTerm(lmap, rsfm, meas, 1.0, shares_rates=shares)
    ref_i, ref_r = np.empty((ra.size, N_PHASES)), np.empty((ra.size, N_PHASES))
    for n, (a, d) in enumerate(zip(ra, dec, strict=True)):
        for k, ph in enumerate(phases):
            ref_i[n, k] = _misfit(_lookup(sfm, *_body(geo, a, d, ph, coaxial=shares)), y)
            rm = _lookup(rsfm, *_body(geo, a, d, ph, coaxial=True))
            ref_r[n, k] = _ranging(rm, rsfm.scale, meas)
    e_i, e_r = grid_pass(sfm, geo, y, ra, dec, 16, None, term, workers=1, compiled=compiled)
    assert e_r is not None
    _check(e_i, ref_i)
    _check(e_r, ref_r)


@pytest.mark.skipif(not compiled_available(), reason="numba is not installed")
def test_compiled_loop_equals_numpy_blocks_with_an_epoch_without_phase_vector() -> None:
    """Both ways on one pass with an epoch without a phase vector (a zero observer
    direction, as :func:`speclight.maps.map_geometry.map_coordinates` marks it): the
    intensity misfit is infinite for every axis in both (a NaN window), the ranging term
    counts that epoch's offset as 0 (the centre of mass) in both; elsewhere, and for maps of
    4, 2 and 1 corners per lookup and an odd number of epochs, they agree to float32
    rounding of the sums (the bound of ``_check``), with the same best phases."""
    rng = np.random.default_rng(13)
    geo = _geometry(rng)
    n_b = 2
    lmap = _map(4, [0.0], 1, 2 * n_b)
    rsfm = spin_frame_map(lmap, BODY_AXIS, N_PHASES)
    sfm = spin_frame_map(_map(4, [20.0, 50.0, 90.0], 4, n_b), BODY_AXIS, N_PHASES)
    ra, dec, _ = _candidates()
    y = np.abs(rng.normal(1.0, 0.2, (N_T, n_b)))
    meas = rng.normal(-0.4, 0.2, (N_T, n_b))
    term = RangingTerm(lmap, rsfm, meas, 1.0, shares_rates=False)
    obs = geo.observer_gcrs.copy()
    obs[7] = 0.0  # no phase vector at epoch 7, lit by the Sun or by the laser
    solar_bad = EpochGeometry(geo.sun_gcrs, obs, geo.t_s, geo.period_s)
    i_np, r_np = grid_pass(sfm, solar_bad, y, ra, dec, 5, None, term, compiled=False)
    i_c, r_c = grid_pass(sfm, solar_bad, y, ra, dec, 5, None, term, compiled=True)
    assert np.all(np.isinf(i_np)) and np.all(np.isinf(i_c))
    assert r_np is not None and r_c is not None
    _check(r_c, r_np)
    for angles, n_rolls in (([20.0, 50.0, 90.0], 4), ([20.0, 50.0, 90.0], 1), ([40.0], 4)):
        sfm = spin_frame_map(_map(4, angles, n_rolls, n_b), BODY_AXIS, N_PHASES)  # 4, 2, 2 corners
        i_np, _ = grid_pass(sfm, geo, y, ra, dec, 5, compiled=False)
        i_c, _ = grid_pass(sfm, geo, y, ra, dec, 5, compiled=True)
        _check(i_c, i_np)
    # an odd number of epochs (the compiled loop takes them in pairs), with the ranging term
    odd = EpochGeometry(geo.sun_gcrs[1:], geo.observer_gcrs[1:], geo.t_s[1:], geo.period_s)
    term = RangingTerm(lmap, rsfm, meas[1:], 1.0, shares_rates=False)
    i_np, r_np = grid_pass(sfm, odd, y[1:], ra, dec, 5, None, term, compiled=False)
    i_c, r_c = grid_pass(sfm, odd, y[1:], ra, dec, 5, None, term, compiled=True)
    assert r_np is not None and r_c is not None
    _check(i_c, i_np)
    _check(r_c, r_np)
