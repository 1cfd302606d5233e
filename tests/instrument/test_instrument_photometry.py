"""Count rates and AB magnitudes against closed forms, quadrature and speclite."""

from __future__ import annotations

import astropy.units as u
import numpy as np
import pytest
from scipy.integrate import quad
from speclite.filters import load_filter

from speclight.errors import InputError
from speclight.instrument import (
    ab_magnitude,
    aperture_area_m2,
    band_response,
    count_rate_per_s,
    spectral_flux_W_nm,
)

GRID_NM = np.arange(300.0, 1241.0, 5.0)
H, C = 6.62607015e-34, 299792458.0  # SI 2019 exact constants
K_B = 1.380649e-23


def planck_W_m2_nm(wavelength_nm: np.ndarray | float, temperature_k: float) -> np.ndarray:
    """Blackbody spectral radiance shape, pi B_lambda [W m-2 nm-1] (Planck's law)."""
    lam = np.asarray(wavelength_nm) * 1e-9
    return 2 * np.pi * H * C**2 / lam**5 / np.expm1(H * C / (lam * K_B * temperature_k)) * 1e-9


def test_aperture_area_closed_form_and_bad_values() -> None:
    assert aperture_area_m2(1.0) == pytest.approx(np.pi / 4, rel=1e-15)
    assert aperture_area_m2(0.43, 0.1) == pytest.approx(np.pi / 4 * (0.43**2 - 0.1**2))
    with pytest.raises(InputError, match="must be > 0") as err:
        aperture_area_m2(-0.43)
    assert err.value.field == "telescope.aperture_diameter_m"
    with pytest.raises(InputError, match="smaller than the aperture"):
        aperture_area_m2(0.43, 0.5)


def test_spectral_flux_is_inverse_square() -> None:
    intensity = np.full((2, GRID_NM.size), 3.0)  # W sr-1 nm-1
    t = np.full((2, GRID_NM.size), 0.5)
    flux = spectral_flux_W_nm(intensity, t, 2.0, np.array([1e6, 2e6]))
    assert np.allclose(flux[0], 3.0 * 0.5 * 2.0 / 1e12, rtol=1e-15)
    assert np.allclose(flux[0] / flux[1], 4.0, rtol=1e-15)
    with pytest.raises(InputError, match="range_m"):
        spectral_flux_W_nm(intensity, t, 2.0, np.array([1e6, -1.0]))


def test_count_rate_flat_spectrum_gaussian_band_closed_form() -> None:
    # Flat flux F, constant efficiency eta, Gaussian band exp(-(l-c)^2/2s^2):
    # N = F eta / (h c) * integral l R dl = F eta c_band s sqrt(2 pi) / (h c) (nm -> m 1e-9).
    # The grid covers +-9 sigma, so the truncated tails are < 1e-18.
    flux_w_nm, eta, centre, sigma = 1e-15, 0.8 * 0.6, 650.0, 30.0
    r = band_response(["G-650/30"], GRID_NM)
    n = count_rate_per_s(
        np.full((1, GRID_NM.size), flux_w_nm),
        GRID_NM,
        np.full(GRID_NM.size, 0.8),
        np.full(GRID_NM.size, 0.6),
        r,
    )
    exact = flux_w_nm * eta * centre * 1e-9 * sigma * np.sqrt(2 * np.pi) / (H * C)
    assert n[0, 0] == pytest.approx(exact, rel=1e-12)


def test_count_rate_blackbody_through_filter_matches_quad() -> None:
    # Independent: scipy quad of the continuous integrand (Planck x speclite's piecewise-
    # linear bessell-V x lambda/hc). The 5 nm bin sum differs by the in-bin curvature of
    # the blackbody, (5 nm)^2/24 * |B''/B| ~ 1e-5, and the product of in-bin slopes of B and
    # R at the filter edges, (5^2/12) |B'/B| |R'| / mean(R) ~ 3e-4: tolerance 1e-3.
    f = load_filter("bessell-V")
    wl_f, resp = f.wavelength / 10.0, f.response

    def integrand(lam: float) -> float:
        return float(
            planck_W_m2_nm(lam, 5800.0) * np.interp(lam, wl_f, resp) * lam * 1e-9 / (H * C)
        )

    exact, _ = quad(integrand, wl_f[0], wl_f[-1], points=wl_f[1:-1], limit=200)
    n = count_rate_per_s(
        planck_W_m2_nm(GRID_NM, 5800.0)[None, :],
        GRID_NM,
        np.ones(GRID_NM.size),
        np.ones(GRID_NM.size),
        band_response(["bessell-V"], GRID_NM),
    )
    assert n[0, 0] == pytest.approx(exact, rel=1e-3)


@pytest.mark.parametrize("name", ["bessell-V", "sdss2010-r", "bessell-B", "sdss2010-i"])
def test_ab_magnitude_matches_speclite(name: str) -> None:
    # Same blackbody given to speclite on a fine 1 A grid (its own integration) and to
    # speclight on the 5 nm grid; the quadrature budget is as above (1e-3 relative), i.e.
    # 1.1e-3 mag.
    area = 0.145  # m2
    scale = 1e-13  # a faint target
    fine_a = np.arange(2900.0, 12500.0, 1.0)
    f_lambda = scale * planck_W_m2_nm(fine_a / 10.0, 5800.0)  # W m-2 nm-1
    cgs = f_lambda * 1e3 / 1e1  # W m-2 nm-1 -> erg s-1 cm-2 A-1 (1e7/1e4/10)
    ref = load_filter(name).get_ab_magnitude(
        cgs * u.erg / (u.s * u.cm**2 * u.Angstrom), fine_a * u.Angstrom
    )
    flux = (scale * planck_W_m2_nm(GRID_NM, 5800.0) * area)[None, :]
    mine = ab_magnitude(flux, area, GRID_NM, band_response([name], GRID_NM))[0, 0]
    assert mine == pytest.approx(float(ref), abs=1.1e-3)


def test_flat_3631_jansky_source_is_ab_zero() -> None:
    # Oke & Gunn 1983: AB = 0 is f_nu = 3631 Jy = 3.631e-23 W m-2 Hz-1 at every frequency;
    # f_lambda = f_nu c / lambda^2, written here independently of the package constant.
    lam_m = GRID_NM * 1e-9
    f_lambda = 3631e-26 * C / lam_m**2 * 1e-9  # W m-2 nm-1
    bands = band_response(["G-420/26", "G-950/26", "bessell-V", "sdss2010-z"], GRID_NM)
    mags = ab_magnitude((f_lambda * 0.5)[None, :], 0.5, GRID_NM, bands)
    assert np.allclose(mags, 0.0, atol=1e-12)


def test_dark_and_unobservable_rows() -> None:
    flux = np.zeros((3, GRID_NM.size))
    flux[1] = np.nan
    flux[2] = 1e-15
    bands = band_response(["G-531/26"], GRID_NM)
    mags = ab_magnitude(flux, 1.0, GRID_NM, bands)
    assert np.isnan(mags[:2]).all() and np.isfinite(mags[2]).all()
    rates = count_rate_per_s(flux, GRID_NM, np.ones(GRID_NM.size), np.ones(GRID_NM.size), bands)
    assert rates[0, 0] == 0.0 and np.isnan(rates[1, 0]) and rates[2, 0] > 0
