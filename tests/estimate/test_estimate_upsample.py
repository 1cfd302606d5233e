"""Spectral upsampling from band albedos (reference paper section 5.1, eq. 3-4).

References the code did not produce:

* colour-science's implementation of Jakob & Hanika (2019, doi:10.1111/cgf.13626),
  ``colour.recovery.find_coefficients_Jakob2019`` and ``sd_Jakob2019``, for three bands;
* closed forms: a spectrum built here from known coefficients of the sigmoid-polynomial family
  (eq. 4) must come back, and grey input must give the constant spectrum;
* eq. 3 evaluated here (bin sums written out in the test) on the returned spectrum;
* feasibility by linear programming (``scipy.optimize.linprog``): where no spectrum in [0, 1]
  has the requested band albedos, the fit must say it did not converge.

Every forward model below (eq. 3 and 4) is written out in the test, not taken from
``speclight``.
"""

from __future__ import annotations

import itertools
import warnings

import numpy as np
import pytest
from scipy.optimize import linprog

from speclight.errors import InputError
from speclight.estimate.spectra.upsampling import (
    ALBEDO_CLIP,
    band_albedo,
    inverse_sigmoid,
    sigmoid,
    sigmoid_polynomial,
    upsample,
)

#: The grid of most tests: 400-1000 nm in 5 nm bins [nm].
STEP_NM = 5.0
WL_NM = np.arange(400.0, 1000.0 + 0.5 * STEP_NM, STEP_NM)
#: Band tolerance passed to the solver in the closed-form tests [1].
SOLVER_TOL = 1e-12
#: Band reproduction the upsampling promises for its input [1].
REPRODUCTION_TOL = 1e-3
#: Margin over the first-order error bound for the nonlinearity of S(p) (a pure number).
LINEARISATION_MARGIN = 10.0


def _bin_widths(wl: np.ndarray) -> np.ndarray:
    """Bin widths [nm]: edges half-way between samples, outer bins symmetric."""
    mid = 0.5 * (wl[1:] + wl[:-1])
    edges = np.concatenate(([2 * wl[0] - mid[0]], mid, [2 * wl[-1] - mid[-1]]))
    return np.diff(edges)


def _eq3_weights(response: np.ndarray, wl: np.ndarray) -> np.ndarray:
    """Eq. 3 as bin sums: R_j lambda dl / sum(R_j lambda dl) (h c cancels)."""
    w = response * wl * _bin_widths(wl)
    return w / w.sum(axis=1, keepdims=True)


def _s(x: np.ndarray) -> np.ndarray:
    """Eq. 4, written plainly (fine away from saturation)."""
    return 0.5 + x / (2.0 * np.sqrt(1.0 + x**2))


def _gaussian_bands(n: int, overlap: float, wl: np.ndarray = WL_NM) -> np.ndarray:
    """n Gaussian bands from 430 to 970 nm whose FWHM is ``overlap`` times their spacing."""
    centres = np.linspace(430.0, 970.0, n)
    fwhm = overlap * (centres[1] - centres[0]) if n > 1 else 300.0
    sigma = fwhm / (2.0 * np.sqrt(2.0 * np.log(2.0)))
    return np.exp(-0.5 * ((wl[None, :] - centres[:, None]) / sigma) ** 2)


def _top_hats(edges_nm: list[float], wl: np.ndarray = WL_NM) -> np.ndarray:
    return np.stack(
        [((wl >= lo) & (wl < hi)).astype(float) for lo, hi in itertools.pairwise(edges_nm)]
    )


def _p_error_bound(p: np.ndarray, basis: np.ndarray, weights: np.ndarray, band_err: float) -> float:
    """First-order bound on max |delta p| over the grid for band errors <= ``band_err``.

    With p = basis @ a and rho = weights @ S(p), d rho = J d a with
    J = weights @ (S'(p) basis), so delta p = basis J^-1 delta rho and
    max |delta p| <= ||basis J^-1||_inf max |delta rho|.
    """
    slope = 0.5 / (1.0 + p**2) ** 1.5
    jac = weights @ (slope[:, None] * basis)
    amplification = np.abs(basis @ np.linalg.inv(jac)).sum(axis=1).max()
    return float(LINEARISATION_MARGIN * amplification * band_err)


def _p_of(result) -> np.ndarray:
    """The fitted polynomial's values on the grid, from the returned spectrum (p = S^-1(g))."""
    g = result.reflectance
    return (2 * g - 1) / (2 * np.sqrt(g * (1 - g)))


# --- colour-science (Jakob & Hanika 2019), three bands ----------------------------------------


@pytest.mark.parametrize(
    "rho", [(0.2, 0.5, 0.3), (0.6, 0.3, 0.1), (0.1, 0.4, 0.8), (0.7, 0.65, 0.6)]
)
def test_three_bands_match_colour_jakob2019(rho: tuple[float, float, float]) -> None:
    """Three bands: the spectrum equals colour-science's Jakob & Hanika (2019) fit.

    colour fits ``XYZ = k sum(g S cmf dl)`` with ``k = 100 / sum(S ybar dl)`` by minimising
    CIE Delta E 1976 in L*a*b* relative to the illuminant's white ``XYZ_n``. To make it solve
    eq. 3, the "colour matching functions" are our three band responses, each divided by its
    photon throughput ``sum(R_j lambda dl)`` (times one common factor), and the "illuminant" is
    ``S(lambda) = lambda`` (photon weighting; h c cancels). Then ``XYZ_j / 100`` is exactly the
    photon-weighted band average of eq. 3 and the white point is (1, 1, 1), so L*a*b* is a
    bijection of the three band albedos and Delta E = 0 exactly where eq. 3 holds: the same
    square problem. Both models are quadratics in lambda under the same sigmoid (colour's in
    ``(lambda - 400) / 600``, ours Legendre in ``(lambda - 700) / 300``), both integrate with
    constant 5 nm bins on this uniform grid. colour stops at Delta E <= 1e-6; its remaining
    band error is measured here with eq. 3, and the spectra may differ by the propagation of
    both fits' band errors.
    """
    colour = pytest.importorskip("colour")
    from colour.recovery import find_coefficients_Jakob2019, sd_Jakob2019

    shape = colour.SpectralShape(400, 800, 5)
    wl = shape.wavelengths
    response = np.stack(
        [
            np.exp(-0.5 * ((wl - c) / s) ** 2)
            for c, s in ((470.0, 34.0), (570.0, 38.0), (680.0, 42.0))
        ]
    )
    throughput = (response * wl * 5.0).sum(axis=1)
    cmfs = colour.MultiSpectralDistributions(
        (response / throughput[:, None] * throughput[1]).T, wl, labels=("b0", "b1", "b2")
    )
    illuminant = colour.SpectralDistribution(wl.copy(), wl)
    target = np.asarray(rho)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # colour's optional-dependency notices
        coefficients, _ = find_coefficients_Jakob2019(target, cmfs, illuminant, max_error=1e-6)
    g_colour = np.asarray(sd_Jakob2019(coefficients, shape).values)
    weights = _eq3_weights(response, wl)
    colour_band_err = float(np.abs(weights @ g_colour - target).max())
    assert colour_band_err < 1e-6  # colour did solve eq. 3 (to its Delta E stop)

    result = upsample(target, response, wl, tol=SOLVER_TOL)
    assert result.converged

    p_colour = np.polyval(coefficients, wl)  # colour's dimensionalised c0 l^2 + c1 l + c2
    basis = np.vander(wl, 3)
    bound = _p_error_bound(p_colour, basis, weights, colour_band_err + SOLVER_TOL)
    assert np.max(np.abs(_p_of(result) - p_colour)) <= bound
    # |dg| = S'(p) |dp| <= |dp| / 2
    assert np.max(np.abs(result.reflectance - g_colour)) <= 0.5 * bound
    assert bound < 1e-4  # the comparison is tight, not vacuous


# --- closed form: a spectrum of the model family comes back ------------------------------------


@pytest.mark.parametrize(
    ("n", "true_coefficients"),
    [
        (3, [0.4, -1.2, 1.5]),
        (5, [-0.3, 2.0, -1.0, -3.0, 2.5]),
        (7, [0.2, 1.0, -4.0, 3.0, 5.0, -6.0, 2.0]),
    ],
)
def test_in_family_spectrum_is_recovered(n: int, true_coefficients: list[float]) -> None:
    """A sigmoid polynomial of order n - 1 (built here as monomials in (lambda - 400) / 600,
    another basis and scaling than the code's) integrated with eq. 3 into n band albedos
    through overlapping Gaussian bands must be recovered: the square system has this exact
    solution. The tolerance propagates the solver's band tolerance through the inverse
    Jacobian of eq. 3 at the true coefficients (first order, times a margin)."""
    t = (WL_NM - 400.0) / 600.0
    basis = np.vander(t, n, increasing=True)
    p_true = basis @ np.asarray(true_coefficients)
    g_true = _s(p_true)
    response = _gaussian_bands(n, overlap=1.0)
    weights = _eq3_weights(response, WL_NM)
    rho = weights @ g_true

    result = upsample(rho, response, WL_NM, tol=SOLVER_TOL)
    assert result.converged
    bound = _p_error_bound(p_true, basis, weights, SOLVER_TOL)
    assert bound < 1e-5
    assert np.max(np.abs(_p_of(result) - p_true)) <= bound
    assert np.max(np.abs(result.reflectance - g_true)) <= 0.5 * bound
    # the coefficients evaluate back to the same spectrum
    again = sigmoid_polynomial(result.coefficients, WL_NM, result.centre_nm, result.half_span_nm)
    np.testing.assert_allclose(again, result.reflectance, rtol=0, atol=1e-14)


# --- self-consistency: the spectrum reproduces the input bands ---------------------------------


@pytest.mark.parametrize("n", [3, 5, 7, 10])
def test_random_albedos_are_reproduced(n: int) -> None:
    """Random albedos in (0.05, 0.95) through overlapping bands (FWHM 0.7 x spacing): eq. 3
    of the returned spectrum, evaluated here, gives the input back to 1e-3."""
    rng = np.random.default_rng(20190 + n)
    response = _gaussian_bands(n, overlap=0.7)
    weights = _eq3_weights(response, WL_NM)
    for _ in range(5):
        rho = rng.uniform(0.05, 0.95, n)
        result = upsample(rho, response, WL_NM)
        assert result.converged
        assert np.all((result.reflectance >= 0) & (result.reflectance <= 1))
        reproduced = weights @ result.reflectance
        assert np.max(np.abs(reproduced - rho)) <= REPRODUCTION_TOL
        np.testing.assert_allclose(result.albedo_fit, reproduced, rtol=0, atol=1e-12)
        assert result.max_band_error == pytest.approx(np.max(np.abs(reproduced - rho)), abs=1e-12)


def test_non_uniform_grid_and_response_shape() -> None:
    """A non-uniform grid (bin widths computed here) and a response x QE-like slope."""
    rng = np.random.default_rng(7)
    wl = np.sort(rng.uniform(400.0, 1000.0, 150))
    response = _gaussian_bands(5, overlap=0.8, wl=wl) * np.linspace(1.0, 0.3, wl.size)
    rho = np.array([0.3, 0.45, 0.2, 0.6, 0.5])
    result = upsample(rho, response, wl)
    assert result.converged
    assert np.max(np.abs(_eq3_weights(response, wl) @ result.reflectance - rho)) <= 1e-8


def test_band_albedo_is_eq3() -> None:
    """band_albedo equals eq. 3 written out here, on a non-uniform grid."""
    wl = np.array([400.0, 410.0, 430.0, 460.0, 500.0, 550.0, 610.0])
    response = np.array([[1.0, 1.0, 0.5, 0.0, 0.0, 0.0, 0.0], [0.0, 0.2, 0.7, 1.0, 1.0, 0.6, 0.1]])
    g = np.array([0.1, 0.2, 0.4, 0.3, 0.5, 0.9, 0.7])
    expected = (response * g * wl * _bin_widths(wl)).sum(1) / (response * wl * _bin_widths(wl)).sum(
        1
    )
    np.testing.assert_allclose(band_albedo(g, response, wl), expected, rtol=1e-14)


def test_infeasible_albedos_are_reported_not_converged() -> None:
    """Strongly overlapping bands (FWHM 1.5 x spacing) with albedos that no spectrum in
    [0, 1] can produce (linprog finds no feasible spectrum): converged must be False and the
    band error must say by how much it missed."""
    response = _gaussian_bands(5, overlap=1.5)
    weights = _eq3_weights(response, WL_NM)
    rho = np.array([0.9, 0.1, 0.9, 0.1, 0.9])
    lp = linprog(np.zeros(WL_NM.size), A_eq=weights, b_eq=rho, bounds=(0, 1))
    assert lp.status == 2  # infeasible
    result = upsample(rho, response, WL_NM)
    assert not result.converged
    assert result.max_band_error > 1e-3
    assert np.all(np.isfinite(result.reflectance))
    assert np.all((result.reflectance >= 0) & (result.reflectance <= 1))


# --- edge cases --------------------------------------------------------------------------------


@pytest.mark.parametrize("value", [0.0, 1e-6, 0.5, 0.9, 1 - 1e-6, 1.0])
def test_grey_input_is_the_constant_spectrum(value: float) -> None:
    """All albedos equal: the constant spectrum exactly, coefficients (S^-1(value), 0, 0)."""
    response = _gaussian_bands(3, overlap=1.0)
    result = upsample([value] * 3, response, WL_NM)
    assert result.converged
    assert np.all(result.reflectance == value)
    assert result.max_band_error <= 1e-15
    expected_c0 = {0.0: -np.inf, 1.0: np.inf, 0.5: 0.0, 0.9: 0.8 / 0.6}.get(value)
    if expected_c0 is not None:
        assert result.coefficients[0] == pytest.approx(expected_c0, rel=1e-15)
    assert np.all(result.coefficients[1:] == 0)
    again = sigmoid_polynomial(result.coefficients, WL_NM, result.centre_nm, result.half_span_nm)
    np.testing.assert_allclose(again, value, rtol=1e-12, atol=0)


@pytest.mark.parametrize("value", [0.0, 0.37, 1.0])
def test_one_band_is_a_constant(value: float) -> None:
    result = upsample([value], _top_hats([500.0, 600.0]), WL_NM)
    assert result.coefficients.shape == (1,)
    assert np.all(result.reflectance == value)


@pytest.mark.parametrize(
    "rho", [(0.0, 0.5, 1.0), (1e-6, 0.3, 0.6), (1 - 1e-6, 0.2, 0.2), (0.0, 1.0, 0.0)]
)
def test_saturated_albedos_are_clipped_with_a_bounded_cost(rho: tuple[float, ...]) -> None:
    """Albedos at or within ALBEDO_CLIP of 0 or 1 are fitted at the clip (finite
    coefficients); the cost is the clip distance, at most ALBEDO_CLIP per band."""
    response = _top_hats([400.0, 600.0, 800.0, 1005.0])
    target = np.asarray(rho)
    result = upsample(target, response, WL_NM)
    assert result.converged
    assert np.all(np.isfinite(result.coefficients))
    reproduced = _eq3_weights(response, WL_NM) @ result.reflectance
    clipped = np.clip(target, ALBEDO_CLIP, 1 - ALBEDO_CLIP)
    assert np.max(np.abs(reproduced - clipped)) <= 1e-8
    assert np.max(np.abs(reproduced - target)) <= ALBEDO_CLIP + 1e-8
    assert result.max_band_error == pytest.approx(np.max(np.abs(clipped - target)), abs=1e-8)


def test_sigmoid_closed_forms() -> None:
    """Eq. 4 at known points, its tails 1 / (4 x^2), and the inverse."""
    assert sigmoid(0.0) == 0.5
    assert sigmoid(1.0) == pytest.approx(0.5 + 1 / (2 * np.sqrt(2)), rel=1e-15)
    assert sigmoid(-1e6) == pytest.approx(0.25e-12, rel=1e-9)
    assert 1 - sigmoid(1e6) == pytest.approx(0.25e-12, rel=1e-3)
    assert sigmoid(-np.inf) == 0.0 and sigmoid(np.inf) == 1.0
    x = np.linspace(-40, 40, 81)
    np.testing.assert_allclose(inverse_sigmoid(sigmoid(x)), x, rtol=1e-9, atol=1e-12)


# --- bad input ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("albedo", "response", "wl", "field"),
    [
        ([[0.2, 0.3]], np.ones((2, 4)), [400.0, 500.0, 600.0, 700.0], "albedo"),
        ([0.2, np.nan], np.ones((2, 4)), [400.0, 500.0, 600.0, 700.0], "albedo"),
        ([0.2, 1.2], np.ones((2, 4)), [400.0, 500.0, 600.0, 700.0], "albedo"),
        ([-0.1, 0.2], np.ones((2, 4)), [400.0, 500.0, 600.0, 700.0], "albedo"),
        ([0.2, 0.3, 0.4], np.ones((2, 4)), [400.0, 500.0, 600.0, 700.0], "albedo"),
        ([0.2, 0.3], np.ones((2, 5)), [400.0, 500.0, 600.0, 700.0], "band_response"),
        ([0.2, 0.3], np.ones(4), [400.0, 500.0, 600.0, 700.0], "band_response"),
        ([0.2, 0.3], [[1, 1, 1, 1], [1, -1, 1, 1]], [400.0, 500.0, 600.0, 700.0], "band_response"),
        ([0.2, 0.3], [[1, 1, 1, 1], [1, np.nan, 1, 1]], [400, 500, 600, 700], "band_response"),
        ([0.2, 0.3], [[1, 1, 1, 1], [0, 0, 0, 0]], [400.0, 500.0, 600.0, 700.0], "band_response"),
        ([0.2, 0.3, 0.4], np.ones((3, 2)), [400.0, 500.0], "band_response"),
        ([0.2, 0.3], np.ones((2, 4)), [400.0, 600.0, 500.0, 700.0], "wavelength_nm"),
        ([0.2, 0.3], np.ones((2, 4)), [[400.0, 500.0, 600.0, 700.0]], "wavelength_nm"),
    ],
)
def test_bad_input_names_the_argument(albedo, response, wl, field: str) -> None:
    with pytest.raises(InputError) as err:
        upsample(albedo, response, wl)
    assert err.value.field == field
    assert field in str(err.value)


def test_bad_options_and_band_albedo_shape() -> None:
    response = _top_hats([400.0, 600.0, 1005.0])
    with pytest.raises(InputError, match="clip"):
        upsample([0.2, 0.3], response, WL_NM, clip=0.0)
    with pytest.raises(InputError, match="tol"):
        upsample([0.2, 0.3], response, WL_NM, tol=-1.0)
    with pytest.raises(InputError, match="reflectance"):
        band_albedo(np.ones(5), response, WL_NM)
