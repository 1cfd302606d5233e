"""Spin-axis search: hand-worked misfits and minima, and a synthetic map whose answer is known.

References: the misfit's definition (mean over epochs and bands of the squared difference of
light curves each divided by its mean), worked by hand; the spin model's definition (the
body turns right-handedly about the inertial axis by 360 deg per period, body x on the
ascending node at phase 0; docs/scenario.md), written out here with Rodrigues' formula
instead of the package's quaternions; and a map given in closed form.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.estimate.spin_axis.spin_axis_core import (
    angular_distance_deg,
    check_search_options,
    local_minima,
    misfit_from_sums,
    radec_grid,
    spin_axis_search,
)
from speclight.estimate.spin_axis.spin_axis_lookup import EpochGeometry, spin_frame_map
from speclight.maps.map_geometry import healpix_directions
from speclight.maps.map_lookup import MapHeader, ReflectivityMap


def _misfit(p: np.ndarray, y: np.ndarray) -> float:
    s1, s2, sy = p.sum(0)[:, None], (p**2).sum(0)[:, None], (p * y / y.mean(0)).sum(0)[:, None]
    return float(misfit_from_sums(s1, s2, sy, ((y / y.mean(0)) ** 2).sum(0), len(p))[0])


def test_misfit_worked_by_hand() -> None:
    # proportional curves: identical after normalisation -> 0
    assert _misfit(np.array([[1.0], [2.0], [3.0]]), np.array([[2.0], [4.0], [6.0]])) == 0.0
    # p = (1, 1) -> (1, 1); y = (1, 3) -> (0.5, 1.5): mean of 0.25 and 0.25
    assert _misfit(np.array([[1.0], [1.0]]), np.array([[1.0], [3.0]])) == pytest.approx(0.25)
    # two bands: band 1 fits (0), band 2 as above (0.25 per epoch): mean over 4 = 0.125
    p = np.array([[1.0, 1.0], [2.0, 1.0]])
    y = np.array([[3.0, 1.0], [6.0, 3.0]])
    assert _misfit(p, y) == pytest.approx(0.125)
    # a prediction of mean 0 cannot be normalised: infinite misfit
    assert _misfit(np.array([[1.0], [-1.0]]), np.array([[1.0], [2.0]])) == np.inf


def test_local_minima_wrap_in_ra_and_sort() -> None:
    e = np.full((5, 8), 10.0)
    e[2, 0], e[2, 7] = 1.0, 1.5  # neighbours across RA 0/360: only the lower is a minimum
    e[4, 4] = 3.0  # on the Dec edge
    np.testing.assert_array_equal(local_minima(e), [2 * 8 + 0, 4 * 8 + 4])


def test_grid_and_options() -> None:
    ra, dec = radec_grid(30.0)
    np.testing.assert_allclose(ra, np.arange(0, 360, 30.0))
    np.testing.assert_allclose(dec, [-75, -45, -15, 15, 45, 75])
    assert angular_distance_deg(10, 0, 190, 0) == pytest.approx(180.0)
    assert angular_distance_deg(0, 89, 180, 89) == pytest.approx(2.0)
    for grid, phases in ((0, 36), (-5, 36), (91, 36), (np.nan, 36), (10, 0)):
        with pytest.raises(InputError):
            check_search_options(grid, phases)


# --- a synthetic map in closed form -------------------------------------------------------

BRIGHT = np.array([0.6, -0.48, 0.64])  # unit: the one bright body direction of band 0


def _rates(d: np.ndarray) -> np.ndarray:
    """Band rates of a body-frame phase vector (coaxial light): band 0 a bright lobe about
    BRIGHT, band 1 brighter towards +x, both smooth and > 0."""
    lobe = 1.0 + 4.0 * np.clip(d @ BRIGHT, 0.0, None) ** 4
    return np.stack([lobe, 2.0 + d[:, 0] + 0.5 * d[:, 2] ** 2], axis=-1)


def _closed_form_map(nside: int) -> ReflectivityMap:
    dirs = healpix_directions(nside)
    header = MapHeader(
        path=Path("synthetic"),
        nside=nside,
        wavelength_nm=np.array([500.0]),
        band_names=["b0", "b1"],
        phase_angle_deg=np.array([0.0]),
        roll_deg=np.array([0.0]),
        attrs={},
    )
    rates = _rates(dirs).astype(np.float32)[:, None, None, :]
    return ReflectivityMap(header, dirs, rates)


def _rodrigues(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    a = np.asarray(angle)[..., None, None]
    return np.eye(3) + np.sin(a) * k + (1 - np.cos(a)) * (k @ k)


def _body_directions(v: np.ndarray, ra: float, dec: float, phase0: float, t, period) -> np.ndarray:
    """Inertial unit vectors (T, 3) in the body frame of the spin model (module docstring)."""
    r, d = np.radians(ra), np.radians(dec)
    z = np.array([np.cos(d) * np.cos(r), np.cos(d) * np.sin(r), np.sin(d)])
    x = np.cross([0.0, 0.0, 1.0], z)
    x /= np.linalg.norm(x)
    frame = np.stack([x, np.cross(z, x), z], axis=-1)  # body -> inertial at phase 0
    rot = _rodrigues(np.array([0.0, 0.0, 1.0]), np.radians(phase0) + 2 * np.pi * t / period)
    body_to_inertial = np.einsum("ij,tjk->tik", frame, rot)
    return np.einsum("tji,tj->ti", body_to_inertial, v)


@pytest.mark.parametrize(("ra", "dec", "phase0"), [(40.0, 25.0, 50.0), (250.0, -60.0, 300.0)])
def test_synthetic_map_gives_the_axis_it_was_made_with(ra, dec, phase0) -> None:
    bmap = _closed_form_map(16)
    period, n = 37.0, 200
    t = np.linspace(0.0, 150.0, n)
    # a line of sight that sweeps 60 deg across the sky during the pass (coaxial light)
    ang = np.radians(np.linspace(-30, 30, n))
    los = np.stack([np.cos(ang) * 0.8, np.sin(ang) * 0.8, np.full(n, 0.6)], -1)
    y = _rates(_body_directions(los, ra, dec, phase0, t, period))
    geo = EpochGeometry(los, los, t, period)
    grid = 10.0
    sfm = spin_frame_map(bmap, None, 36)
    res = spin_axis_search(bmap, sfm, geo, y, ["b0", "b1"], grid, None, do_refine=True)
    best_ra, best_dec, best_phase, best_err = res.best
    # the cell nearest the truth is at most half a diagonal away: grid / sqrt(2)
    assert angular_distance_deg(best_ra, best_dec, ra, dec) <= grid / np.sqrt(2)
    assert abs(np.angle(np.exp(1j * np.radians(best_phase - phase0)), deg=True)) <= 10.0
    # refinement with the map's own interpolation: the truth within the map's pixel (3.7 deg
    # at nside 16), and a misfit at least 10x below the best cell's
    r_ra, r_dec, r_phase, r_err = res.refined
    assert angular_distance_deg(r_ra, r_dec, ra, dec) < 3.7
    assert abs(np.angle(np.exp(1j * np.radians(r_phase - phase0)), deg=True)) < 3.7
    assert r_err < best_err / 10
    # the error surface is saved on the grid, its minimum where the best cell is
    i, j = np.unravel_index(np.argmin(res.error), res.error.shape)
    assert (res.ra_deg[i], res.dec_deg[j]) == (best_ra, best_dec)


def _sweeping_pass(n: int = 200) -> tuple[np.ndarray, np.ndarray]:
    t = np.linspace(0.0, 150.0, n)
    ang = np.radians(np.linspace(-30, 30, n))
    los = np.stack([np.cos(ang) * 0.8, np.sin(ang) * 0.8, np.full(n, 0.6)], -1)
    return t, los


def test_a_synodic_period_gives_each_axis_its_sidereal_period() -> None:
    # the pass made with a sidereal period; the search given the synodic one of the true
    # axis by the linear relation 1/P_syn = 1/P_sid - Omega/(2 pi) (Harris et al. 1984),
    # Omega computed here from the line of sight's azimuth about the true axis
    from speclight.estimate.spin_axis.spin_axis_period import bisector_rates

    ra, dec, phase0, p_sid = 40.0, 25.0, 50.0, 37.0
    t, los = _sweeping_pass()
    y = _rates(_body_directions(los, ra, dec, phase0, t, p_sid))
    geo = EpochGeometry(los, los, t, p_sid)
    omega = float(bisector_rates(geo, np.array([ra]), np.array([dec]))[0])
    p_syn = 1.0 / (1.0 / p_sid - omega / (2 * np.pi))
    assert abs(p_syn - p_sid) / p_sid > 0.005  # a shift the grid would not tolerate
    bmap = _closed_form_map(16)
    sfm = spin_frame_map(bmap, None, 36)
    geo_syn = EpochGeometry(los, los, t, p_syn)
    res = spin_axis_search(bmap, sfm, geo_syn, y, ["b0", "b1"], 10.0, period_kind="auto")
    assert res.period_kind == "synodic"
    assert res.period_kind_errors["synodic"] < res.period_kind_errors["sidereal"]
    # the refined axis within the map's pixel (3.7 deg at nside 16), its period the truth's
    # to the accuracy the axis gives it (dP/P = P Omega'/(2 pi), well below 0.5 %)
    assert angular_distance_deg(res.refined[0], res.refined[1], ra, dec) < 3.7
    assert res.refined_period_s == pytest.approx(p_sid, rel=5e-3)
    assert res.confidence is not None and res.confidence.constrained


def test_a_map_without_attitude_signal_is_said_not_to_constrain_the_axis() -> None:
    # a Lambertian sphere's light depends on the phase angle alone; coaxial light: a constant
    bmap = _closed_form_map(8)
    flat = np.ones_like(bmap.intensity_W_sr_nm)
    bmap = ReflectivityMap(bmap.header, bmap.direction_body, flat)
    t, los = _sweeping_pass()
    rng = np.random.default_rng(2)
    y = 1.0 + 0.01 * rng.normal(size=(t.size, 2))
    res = spin_axis_search(
        bmap, spin_frame_map(bmap, None, 12), EpochGeometry(los, los, t, 37.0), y,
        ["b0", "b1"], 30.0,
    )  # fmt: skip
    assert res.confidence is not None and not res.confidence.constrained
    assert res.confidence.note.startswith("the data do not constrain the axis")


#: The period [s] of :func:`_noisy_pass`.
P_TRUE_S = 37.0


def _noisy_pass() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The sweeping pass made with the axis RA 40, Dec 25 deg, phase 50 deg and the period
    :data:`P_TRUE_S`, 1 % noise (seed 4): epochs [s], lines of sight, rates."""
    t, los = _sweeping_pass()
    rng = np.random.default_rng(4)
    y = _rates(_body_directions(los, 40.0, 25.0, 50.0, t, P_TRUE_S))
    return t, los, y * (1 + 0.01 * rng.normal(size=y.shape))


@pytest.mark.parametrize("wrong", [False, True])
def test_a_wrong_fixed_period_is_warned_and_the_true_one_is_not(wrong) -> None:
    # the pass made with P = 37 s and 1 % noise; searched with the period fixed at the truth
    # and at 6 % off (a phase drift of 86 deg over the pass's four turns: the reference
    # that decides is the period the data were made with)
    t, los, y = _noisy_pass()
    p_true = P_TRUE_S
    given = p_true * 1.06 if wrong else p_true
    bmap = _closed_form_map(16)
    res = spin_axis_search(
        bmap, spin_frame_map(bmap, None, 36), EpochGeometry(los, los, t, given), y,
        ["b0", "b1"], 10.0, period_kind="sidereal",
    )  # fmt: skip
    check, conf = res.period_check, res.confidence
    assert check is not None and conf is not None
    assert check.warn is wrong
    if wrong:
        # the scan's step: two 10-deg phase steps of drift over the 150 s pass
        step = 2 * given / (36 * 150.0)
        assert check.preferred_period_s == pytest.approx(p_true, rel=step)
        assert check.preferred_misfit < check.given_misfit
        assert not conf.constrained and conf.note.startswith(check.note)
        assert "the given period may be wrong" in conf.note
    else:
        assert conf.constrained and "period" not in conf.note


@pytest.mark.parametrize("bound", [0.03, 0.10])
def test_a_free_period_stopped_by_its_bound_is_said(bound) -> None:
    # the pass of the test above made with P = 37 s, the search started 6 % off with the
    # period free within `bound`: within 3 % the truth is out of reach and the answer sits
    # on the bound's edge (said, axis not called constrained); within 10 % the truth is
    # inside and found (no edge note)
    t, los, y = _noisy_pass()
    p_true = P_TRUE_S
    given = p_true * 1.06
    bmap = _closed_form_map(16)
    res = spin_axis_search(
        bmap, spin_frame_map(bmap, None, 36), EpochGeometry(los, los, t, given), y,
        ["b0", "b1"], 10.0, period_kind="sidereal", period_bound=bound,
    )  # fmt: skip
    conf = res.confidence
    assert conf is not None
    if bound < 0.06:
        assert res.refined_period_s == pytest.approx(given * (1 - bound), rel=0.02 * bound)
        assert not conf.constrained
        assert conf.note.startswith("the free period ended at the lower edge")
    else:
        # the period to the scan's step (two 10-deg phase steps of drift over the pass)
        assert res.refined_period_s == pytest.approx(p_true, rel=2 * given / (36 * 150.0))
        assert "edge" not in conf.note


def test_a_flat_surface_skips_the_period_check() -> None:
    # the Lambertian case (above): the flat surface is said; no period check is run
    bmap = _closed_form_map(8)
    bmap = ReflectivityMap(bmap.header, bmap.direction_body, np.ones_like(bmap.intensity_W_sr_nm))
    t, los = _sweeping_pass()
    y = 1.0 + 0.01 * np.random.default_rng(2).normal(size=(t.size, 2))
    res = spin_axis_search(
        bmap, spin_frame_map(bmap, None, 12), EpochGeometry(los, los, t, 37.0), y,
        ["b0", "b1"], 30.0,
    )  # fmt: skip
    assert res.period_check is None
    assert res.confidence is not None and "period" not in res.confidence.note


def test_map_error_variance_is_the_shift_on_the_half_resolution_map_over_three() -> None:
    # reference: the answer refitted on the map at half its nside by Nelder-Mead on the spin
    # model's own misfit (quaternions, not the tangent parametrisation); the variance on each
    # axis component is (shift / 3)^2 (bilinear interpolation errs by k h^2: module doc)
    from scipy.optimize import minimize

    from speclight.estimate.spin_axis.spin_axis_continuation import coarsen_map
    from speclight.estimate.spin_axis.spin_axis_gradient import SpinMisfit
    from speclight.estimate.spin_axis.spin_axis_jackknife import map_error_covariance
    from speclight.estimate.spin_axis.spin_axis_misfit import exact_misfit

    ra, dec, phase0, period = 40.0, 25.0, 50.0, 37.0
    t, los = _sweeping_pass()
    y = _rates(_body_directions(los, ra, dec, phase0, t, period))
    geo = EpochGeometry(los, los, t, period)
    bmap = _closed_form_map(16)
    model = SpinMisfit.around(bmap, geo, y, None, ra, dec)
    x0 = np.array([0.0, 0.0, np.radians(phase0)])
    cov = map_error_covariance(model, x0)
    coarse = coarsen_map(bmap, 8, None)
    got = minimize(
        lambda v: exact_misfit(coarse, geo, y, None, *v), [ra, dec, phase0],
        method="Nelder-Mead", options={"xatol": 1e-4, "fatol": 1e-14, "maxiter": 4000},
    )  # fmt: skip
    shift_deg = angular_distance_deg(got.x[0], got.x[1], ra, dec)
    assert shift_deg > 0.05  # the coarse map's error moves the answer
    sigma_deg = np.degrees(np.sqrt(np.diag(cov)[:2]))
    # both optimisers stop within ~1e-3 deg of their minimum
    np.testing.assert_allclose(sigma_deg, shift_deg / 3, atol=2e-3)
    assert np.all(cov[2:] == 0) and np.all(cov[:, 2:] == 0)
    # nothing coarser than nside 1: no term
    assert not np.any(
        map_error_covariance(
            SpinMisfit.around(coarsen_map(bmap, 1, None), geo, y, None, ra, dec), x0
        )
    )
