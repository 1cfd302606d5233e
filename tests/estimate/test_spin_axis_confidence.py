"""Spin-axis uncertainties and the synodic period: closed forms and textbook estimators.

References: the synodic-sidereal relation ``1 / P_sid = 1 / P_syn + Omega / (2 pi)`` (Harris
et al. 1984, Icarus 57, 251; Pravec et al. 2005) with a phase vector turning uniformly about
an axis by construction; the least-squares covariance ``sigma^2 (X^T X)^-1`` of a straight
line fit with white noise (any regression textbook; the sandwich estimator reduces to it,
White 1980); the variance of second differences of white noise, ``6 sigma^2``.
"""

from __future__ import annotations

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.estimate.spin_axis.spin_axis_confidence import (
    AxisConfidence,
    _verdict,
    noise_floor,
    sandwich_covariance,
)
from speclight.estimate.spin_axis.spin_axis_lookup import EpochGeometry
from speclight.estimate.spin_axis.spin_axis_period import (
    bisector_rates,
    check_period_kind,
    sidereal_periods,
)
from speclight.estimate.spin_axis.spin_axis_period_scan import scan_periods


def _turning_pass(rate_rad_s: float, n: int = 200) -> EpochGeometry:
    """Sun and observer symmetric about a phase vector in the equator turning at ``rate``
    about +z (GCRS): the phase vector is ``(cos(w t), sin(w t), 0)`` exactly."""
    t = np.linspace(0.0, 600.0, n)
    p = np.stack([np.cos(rate_rad_s * t), np.sin(rate_rad_s * t), np.zeros(n)], -1)
    z = np.array([0.0, 0.0, 1.0])
    half = np.radians(30.0)  # half the phase angle, in the plane of p and z
    sun = np.cos(half) * p + np.sin(half) * z
    obs = np.cos(half) * p - np.sin(half) * z
    return EpochGeometry(sun, obs, t, 100.0)


def test_bisector_rate_and_sidereal_period_closed_form() -> None:
    w = 2e-3  # rad/s: 69 deg over the 600 s pass
    geo = _turning_pass(w)
    rates = bisector_rates(geo, np.array([0.0, 0.0]), np.array([90.0, -90.0]))
    # about +z the azimuth grows at w; about -z (the reverse axis) it falls at w
    np.testing.assert_allclose(rates, [w, -w], rtol=1e-9)
    p_syn = 120.0
    expected = 1.0 / (1.0 / p_syn + w / (2 * np.pi))
    np.testing.assert_allclose(sidereal_periods(p_syn, rates)[0], expected, rtol=1e-12)
    # a bisector turning faster than the light curve's frequency: no sidereal period
    assert np.isnan(sidereal_periods(p_syn, np.array([-1.0]))[0])
    with pytest.raises(InputError, match="period_kind"):
        check_period_kind("apparent")


def test_sandwich_is_the_textbook_covariance_for_white_residuals() -> None:
    # straight line y = a + b t with white noise: C = sigma^2 (X^T X)^-1
    rng = np.random.default_rng(3)
    t = np.linspace(-1.0, 1.0, 4000)
    x = np.stack([np.ones_like(t), t], -1)
    sigma = 0.3
    r = sigma * rng.normal(size=t.size)
    cov, a_inv, _ = sandwich_covariance(r, x, t.size)
    textbook = sigma**2 * np.linalg.inv(x.T @ x)
    # the sandwich's own sampling error: relative ~ sqrt(2 / n) per variance (5 sigma)
    np.testing.assert_allclose(np.diag(cov), np.diag(textbook), rtol=5 * np.sqrt(2 / t.size))
    np.testing.assert_allclose(a_inv, np.linalg.inv(x.T @ x), rtol=1e-9, atol=1e-15)


def test_sandwich_widens_for_correlated_residuals() -> None:
    # AR(1) residuals rho = 0.9: the mean's variance is (1 + rho) / (1 - rho) = 19 times
    # the white-noise formula's (long-run variance of an AR(1) process)
    rng = np.random.default_rng(5)
    n, rho = 20000, 0.9
    e = rng.normal(size=n)
    r = np.empty(n)
    r[0] = e[0]
    for i in range(1, n):
        r[i] = rho * r[i - 1] + np.sqrt(1 - rho**2) * e[i]
    x = np.ones((n, 1))
    cov, _, lag = sandwich_covariance(r, x, n)
    white = np.var(r) / n
    assert lag > 5
    # Bartlett weights at a finite lag are biased low: accept half to all of the factor 19
    assert 0.5 * 19 < cov[0, 0] / white < 1.2 * 19


def test_noise_floor_of_white_noise() -> None:
    rng = np.random.default_rng(7)
    t = np.linspace(0, 600, 3000)
    sigma = 0.02
    curve = 1.0 + 0.3 * np.sin(2 * np.pi * t / 120.0)  # smooth: second differences ~ 0
    y = np.stack([curve * (1 + sigma * rng.normal(size=t.size)) for _ in range(2)], -1)
    # the normalised curve's noise is sigma * curve / mean(curve) = sigma * curve: mean
    # square sigma^2 (1 + 0.3^2 / 2)
    expected = sigma**2 * (1 + 0.045)
    # MAD of 2 x 3000 values: relative standard error of a variance ~ 2 x 1.65 / sqrt(n)
    assert noise_floor(y) == pytest.approx(expected, rel=5 * 3.3 / np.sqrt(6000))


def test_verdicts() -> None:
    flat = AxisConfidence(contrast=1.01, region95_fraction=1.0, sigma_axis_deg=500.0)
    ok, note = _verdict(flat)
    assert not ok and note.startswith("the data do not constrain the axis")
    two = AxisConfidence(
        contrast=8.0, region95_fraction=0.001, sigma_axis_deg=2.0, region95_max_sep_deg=170.0
    )
    ok, note = _verdict(two)
    assert not ok and "second minimum" in note
    good = AxisConfidence(
        contrast=8.0, region95_fraction=0.001, sigma_axis_deg=2.0, region95_max_sep_deg=4.0,
        noise_ratio=50.0, noise_floor=1e-3,
    )  # fmt: skip
    ok, note = _verdict(good)
    assert ok and "times the noise floor" in note
    # a misfit a few times the noise floor (the map's own error; the calibration's draws sit
    # near 4.5): still constrained, the sigmas given first, then what they count of it (the
    # default's: the map's error as a field) or, with the jackknife alone, the warning that
    # they may be too small; near the floor (1.2) nothing more is said
    near = dict(contrast=8.0, region95_fraction=0.001, sigma_axis_deg=2.0, noise_floor=1e-3)
    ok, note = _verdict(AxisConfidence(region95_max_sep_deg=4.0, noise_ratio=4.5, **near))
    assert ok and note.startswith("axis sigma 2 deg")
    assert "4.5 times the noise floor" in note and "directions displaced" in note
    assert "too small" not in note
    shrunk = AxisConfidence(
        region95_max_sep_deg=4.0, noise_ratio=4.5, method="jackknife-shrunk", **near
    )
    ok, note = _verdict(shrunk)
    assert ok and "4.5 times the noise floor" in note and "may be too small" in note
    ok, note = _verdict(AxisConfidence(region95_max_sep_deg=4.0, noise_ratio=1.2, **near))
    assert ok and note.startswith("axis sigma 2 deg") and "noise floor" not in note


def test_scan_steps_drift_two_phase_steps() -> None:
    # 72 phases, 600 s pass, P 120 s: a relative step of 2 P / (K span) = 1/180 drifts
    # 360 x 5 turns / 180 = 10 deg = two 5-deg phase steps
    p = scan_periods(120.0, 0.05, 72, 600.0)
    assert p[0] == pytest.approx(114.0) and p[-1] == pytest.approx(126.0)
    assert np.max(np.diff(p)) / 120.0 <= 1 / 180 + 1e-12


@pytest.mark.parametrize("rho", [0.0, 0.8])
def test_block_jackknife_z_is_students_t_under_the_null(rho) -> None:
    # zero-mean AR(1) values, 10 blocks of 300: the blocks' sums are nearly independent, so
    # z = sum / se is Student's t with 9 degrees of freedom, variance 9 / 7 (for rho = 0.8
    # a white-noise standard error would give (1 + rho) / (1 - rho) = 9 times more)
    from speclight.estimate.spin_axis.spin_axis_period_check import block_jackknife_z

    rng = np.random.default_rng(11)
    n_draws, n = 3000, 3000
    e = rng.normal(size=(n_draws, n))
    d = np.empty_like(e)
    d[:, 0] = e[:, 0]
    for i in range(1, n):
        d[:, i] = rho * d[:, i - 1] + np.sqrt(1 - rho**2) * e[:, i]
    z = np.array([block_jackknife_z(row, 10) for row in d])
    # sampling error of a variance of t(9) values: sqrt((2 + 6 / 5) / n_draws) relative
    assert np.var(z) == pytest.approx(9 / 7, rel=5 * np.sqrt(3.2 / n_draws))
    assert np.isnan(block_jackknife_z(np.ones(5), 10))


def test_jackknife_spread_of_the_mean_is_the_variance_of_the_mean() -> None:
    # delete-one jackknife of the sample mean: its variance estimate is s^2 / n exactly
    # (Efron & Stein 1981; Efron 1982, "The jackknife, the bootstrap...", eq. 3.5)
    from speclight.estimate.spin_axis.spin_axis_jackknife import jackknife_spread

    v = np.random.default_rng(8).normal(size=(12, 2))
    n = v.shape[0]
    refits = (v.sum(axis=0) - v) / (n - 1)  # the mean without each sample
    want = np.cov(v.T, ddof=1) / n
    np.testing.assert_allclose(jackknife_spread(refits), want, rtol=1e-12, atol=1e-15)


def test_confidence_sigmas_are_east_and_north_of_the_spin_model() -> None:
    # reference: the spin model's own conversion of the tangent parameters to RA, Dec
    # (SpinMisfit.to_spin_model, frames and quaternions), differentiated numerically:
    # east = dRA cos(Dec), north = dDec; the covariance propagated through that Jacobian
    from speclight.estimate.spin_axis.spin_axis_confidence import confidence_from_covariance
    from speclight.estimate.spin_axis.spin_axis_gradient import SpinMisfit

    ra, dec = 250.0, -35.0
    geo = _turning_pass(0.0, 20)
    model = SpinMisfit.around(None, geo, np.ones((20, 2)), None, ra, dec)  # type: ignore[arg-type]
    h = 1e-6
    jac = np.zeros((2, 3))
    for k in range(2):
        step = np.zeros(3)
        step[k] = h
        r1, d1 = model.to_spin_model(step)[:2]
        r0, d0 = model.to_spin_model(-step)[:2]
        jac[:, k] = [(r1 - r0) * np.cos(np.radians(dec)) / (2 * h), (d1 - d0) / (2 * h)]
    b = np.random.default_rng(2).normal(size=(3, 3))
    cov = 1e-4 * (b @ b.T + 0.1 * np.eye(3))
    want = jac @ cov @ jac.T  # [deg^2]
    err = np.ones((5, 10))
    err[2, 3] = 0.5
    got = confidence_from_covariance(
        cov, np.eye(3), err, np.linspace(-60, 60, 5), np.arange(10) * 36.0, (ra, dec, 0.0, 0.5),
        1.0 + 0.01 * np.random.default_rng(1).normal(size=(20, 2)),
    )  # fmt: skip
    # central differences of step 1e-6 rad: relative error ~1e-8 (h^2 over the curvature)
    np.testing.assert_allclose(
        [got.sigma_east_deg, got.sigma_north_deg], np.sqrt(np.diag(want)), rtol=1e-6
    )
    rho = want[0, 1] / np.sqrt(want[0, 0] * want[1, 1])
    np.testing.assert_allclose(got.correlation_east_north, rho, atol=1e-6)
    assert abs(rho) > 0.05  # a correlation whose sign is tested


def test_ledoit_wolf_shrinkage_by_hand_and_consistent() -> None:
    # Ledoit & Wolf (2004) Lemma 3.2 worked by hand for deviations (+-1, 0), (0, 0) twice:
    # S = diag(1/2, 0), mu = 1/4, delta^2 = 1/8, beta^2 = (1/4) / 4 = 1/16: lambda = 1/2;
    # (G - 1) (lambda mu I + (1 - lambda) S) = 3 diag(3/8, 1/8)
    from speclight.estimate.spin_axis.spin_axis_jackknife import (
        jackknife_spread,
        shrunk_jackknife_spread,
    )

    xs = np.array([[1.0, 0.0, 0.2], [-1.0, 0.0, 0.2], [0.0, 0.0, 0.2], [0.0, 0.0, 0.2]])
    cov, lam = shrunk_jackknife_spread(xs)
    np.testing.assert_allclose(lam, 0.5, rtol=1e-12)
    np.testing.assert_allclose(cov[:2, :2], np.diag([9 / 8, 3 / 8]), rtol=1e-12)
    # the target keeps the trace (mu = trace / 2); with many refits of a clearly
    # anisotropic spread the intensity goes to 0 (their Theorem 3.2): beta^2 ~ 1 / G
    v = np.random.default_rng(4).normal(size=(4000, 3)) * [1.0, 0.1, 1.0]
    cov, lam = shrunk_jackknife_spread(v)
    plain = jackknife_spread(v)
    np.testing.assert_allclose(np.trace(cov[:2, :2]), np.trace(plain[:2, :2]), rtol=1e-12)
    assert lam < 0.01
    np.testing.assert_allclose(cov, plain, rtol=0.02, atol=0.02 * plain[0, 0])


def test_shrinkage_leaves_the_period_variance_alone() -> None:
    # by hand for deviations (a_e, a_n, phase, f) = (+-1, 0, 0, +-2), (0, 0, 0, +-1): the
    # axis block is the worked example above (lambda = 1/2, block diag(3/8, 1/8)); the plain
    # second moment 1/G sum d d^T has S_ff = (4 + 4 + 1 + 1) / 4 = 5/2 and S_ef = 4 / 4 = 1:
    # only the axis block is shrunk, so S_ff stays 5/2 (it was halved, (1 - lambda) S_ff,
    # with the target zero there) and the cross term goes with 1 - lambda
    from speclight.estimate.spin_axis.spin_axis_jackknife import shrunk_second_moment

    d = np.array([[1.0, 0, 0, 2], [-1.0, 0, 0, -2], [0.0, 0, 0, 1], [0.0, 0, 0, -1]])
    got, lam = shrunk_second_moment(d)
    np.testing.assert_allclose(lam, 0.5, rtol=1e-12)
    np.testing.assert_allclose(got[:2, :2], np.diag([3 / 8, 1 / 8]), rtol=1e-12)
    np.testing.assert_allclose(got[3, 3], 5 / 2, rtol=1e-12)
    np.testing.assert_allclose(got[0, 3], 1 / 2, rtol=1e-12)
    np.testing.assert_allclose(got[2, :], 0.0, atol=1e-15)
    # a convex sum of two positive semi-definite matrices: no negative eigenvalue beyond
    # rounding of entries of order 1
    r = np.random.default_rng(5).normal(size=(6, 4)) * [1.0, 0.2, 0.5, 3.0]
    assert np.min(np.linalg.eigvalsh(shrunk_second_moment(r)[0])) > -1e-12


def test_free_period_sigmas_are_marginal_and_said() -> None:
    # reference: the marginal variance of a Gaussian's component is its diagonal entry, the
    # conditional (the period known) the Schur complement C_ee - C_ef^2 / C_ff, smaller where
    # they correlate; the tangent parameter x[1] is the axis's east (EAST_NORTH)
    from speclight.estimate.spin_axis.spin_axis_confidence import confidence_from_covariance

    cov = np.diag([1e-4, 4e-4, 1e-3, 2e-2])
    cov[1, 3] = cov[3, 1] = 0.8 * np.sqrt(4e-4 * 2e-2)  # east with the extra turn: rho 0.8
    err = np.ones((5, 10))
    err[2, 3] = 0.01
    y = 1.0 + 0.01 * np.random.default_rng(1).normal(size=(20, 2))
    refined = (108.0, 0.0, 0.0, noise_floor(y))  # the best cell; a misfit at the noise floor
    args = (err, np.linspace(-60, 60, 5), np.arange(10) * 36.0, refined)
    got = confidence_from_covariance(cov, np.eye(4), *args, y, 0, 2.0)
    conditional = np.sqrt(4e-4 * (1 - 0.8**2))
    np.testing.assert_allclose(got.sigma_east_deg, np.degrees(np.sqrt(4e-4)), rtol=1e-12)
    assert got.sigma_east_deg > 1.5 * np.degrees(conditional)  # 1 / sqrt(1 - 0.64)
    np.testing.assert_allclose(got.sigma_period_s, 2.0 * np.sqrt(2e-2), rtol=1e-12)
    assert got.constrained and "the period free: the sigmas are marginal" in got.note
    fixed = confidence_from_covariance(cov[:3, :3], np.eye(3), *args, y)
    assert fixed.constrained and "period free" not in fixed.note
