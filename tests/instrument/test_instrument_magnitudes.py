"""Exo-atmospheric, standard (1000 km) and Vega V magnitudes against closed forms and
speclite (issue 14 item 10)."""

from __future__ import annotations

import astropy.units as u
import numpy as np
import pytest
import yaml
from speclite.filters import load_filter

from speclight.instrument import (
    V_AB_MINUS_VEGA,
    ab_magnitude,
    standard_magnitude,
    vega_v_magnitude,
)
from speclight.scenario import example_text, parse_scenario
from speclight.simulation.radiometry import instrument_response

GRID_NM = np.arange(300.0, 1241.0, 5.0)
H, C, K_B = 6.62607015e-34, 299792458.0, 1.380649e-23  # SI 2019 exact constants
#: Magnitude round-off: float64 logs of ratios near 1 [mag].
ROUND_OFF_MAG = 1e-12


def flat_fnu_W_m2_nm(ab_mag: float) -> np.ndarray:
    """f_lambda of a flat-f_nu source of the given AB magnitude: 3631 Jy 10^(-0.4 m) c/lambda^2
    (Oke & Gunn 1983), written independently of the package constant."""
    return 3631e-26 * 10 ** (-0.4 * ab_mag) * C / (GRID_NM * 1e-9) ** 2 * 1e-9


def test_standard_magnitude_at_1000_km_is_the_magnitude_and_follows_5_log10() -> None:
    m = np.array([[7.0, 8.0], [9.5, np.nan], [3.0, 4.0]])
    r = np.array([1.0e6, 2.0e6, 1.0e7])
    std = standard_magnitude(m, r)
    assert std[0] == pytest.approx(m[0], abs=ROUND_OFF_MAG)  # exactly at 1000 km
    assert std[1, 0] == pytest.approx(9.5 - 5 * np.log10(2.0), abs=ROUND_OFF_MAG)
    assert np.isnan(std[1, 1])
    assert std[2] == pytest.approx(m[2] - 5.0, abs=ROUND_OFF_MAG)  # 10x farther: 5 mag
    assert standard_magnitude(np.array([5.0]), np.array([4.0e5]))[0] == pytest.approx(
        5.0 - 5 * np.log10(0.4), abs=ROUND_OFF_MAG
    )


def test_standard_magnitude_is_the_inverse_square_law() -> None:
    # The same target moved from 3000 km to 1000 km: irradiance x 9 by 1/r^2; its AB
    # magnitude at 1000 km computed from that irradiance is the standard magnitude.
    bands = np.stack([np.exp(-0.5 * ((GRID_NM - 600.0) / 40.0) ** 2)])
    at_3000_km = flat_fnu_W_m2_nm(12.0)[None, :]
    m_far = ab_magnitude(at_3000_km, 1.0, GRID_NM, bands)
    m_near = ab_magnitude(at_3000_km * 9.0, 1.0, GRID_NM, bands)
    assert standard_magnitude(m_far, np.array([3.0e6]))[0, 0] == pytest.approx(
        m_near[0, 0], abs=ROUND_OFF_MAG
    )


def test_vega_v_of_a_flat_fnu_source_is_its_ab_magnitude_minus_the_offset() -> None:
    # Blanton & Roweis 2007 (AJ 133, 734), table 1: V_AB - V_Vega = 0.02 for Bessell V, so
    # a 3631 Jy flat f_nu source (AB = 0 in every band) has V = -0.02, one of AB 10: 9.98.
    assert V_AB_MINUS_VEGA == 0.02
    area = 0.3
    flux = np.stack([flat_fnu_W_m2_nm(0.0), flat_fnu_W_m2_nm(10.0)]) * area
    v = vega_v_magnitude(flux, area, GRID_NM)
    assert v is not None
    np.testing.assert_allclose(v, [-0.02, 9.98], atol=ROUND_OFF_MAG)


def test_vega_v_matches_speclite_for_a_blackbody() -> None:
    # speclite integrates the blackbody on a fine 1 A grid with its own bessell-V; the
    # quadrature budget of the 5 nm grid is that of test_ab_magnitude_matches_speclite
    # (1.1e-3 mag).
    area, scale = 0.145, 1e-13
    fine_a = np.arange(2900.0, 12500.0, 1.0)
    lam = fine_a * 1e-10
    planck = 2 * np.pi * H * C**2 / lam**5 / np.expm1(H * C / (lam * K_B * 5800.0)) * 1e-9
    cgs = scale * planck * 1e2  # W m-2 nm-1 -> erg s-1 cm-2 A-1
    ref_ab = load_filter("bessell-V").get_ab_magnitude(
        cgs * u.erg / (u.s * u.cm**2 * u.Angstrom), fine_a * u.Angstrom
    )
    lam_grid = GRID_NM * 1e-9
    planck_grid = (
        2 * np.pi * H * C**2 / lam_grid**5 / np.expm1(H * C / (lam_grid * K_B * 5800.0)) * 1e-9
    )
    v = vega_v_magnitude((scale * planck_grid * area)[None, :], area, GRID_NM)
    assert v is not None
    assert v[0] == pytest.approx(float(ref_ab) - 0.02, abs=1.1e-3)


def test_vega_v_is_absent_when_the_grid_misses_the_v_band() -> None:
    red = np.arange(750.0, 1101.0, 5.0)  # bessell-V ends near 700 nm
    assert vega_v_magnitude(np.ones((2, red.size)), 1.0, red) is None


@pytest.fixture(scope="module")
def loaded():
    data = yaml.safe_load(example_text("calsphere"))
    data["spectrum"] = {"min_nm": 400, "max_nm": 800, "step_nm": 5}
    data["instrument"]["bands"] = [
        {"name": "G-550/30", "gaussian": {"center_nm": 550, "sigma_nm": 30}},
        {"name": "V", "filter": "bessell-V"},
    ]
    del data["instrument"]["noise"]
    return parse_scenario(yaml.safe_dump(data))


def test_exo_atmospheric_magnitude_removes_the_band_weighted_transmission(loaded) -> None:
    wl = np.arange(400.0, 801.0, 5.0)
    n = 3
    intensity = np.tile(1e-3 * (1 + wl / 1000.0), (n, 1))  # W sr-1 nm-1, a sloped spectrum
    range_m = np.array([8e5, 1.5e6, 3e6])
    t = np.ones((n, wl.size))
    t[1] = 0.6  # grey: AB - AB_exo = -2.5 log10 0.6
    t[2] = np.where(wl < 550.0, 0.5, 0.9)  # a step across the bands
    rad = instrument_response(loaded, wl, intensity, t, range_m)
    assert rad.ab_magnitude_exo is not None and rad.ab_magnitude_standard is not None
    diff = rad.ab_magnitude - rad.ab_magnitude_exo
    assert diff[0] == pytest.approx([0.0, 0.0], abs=ROUND_OFF_MAG)  # T = 1: the same
    assert diff[1] == pytest.approx([-2.5 * np.log10(0.6)] * 2, abs=ROUND_OFF_MAG)
    # A spectral T: the extinction is -2.5 log10 of the photon- and band-weighted mean T,
    # sum(f R lambda T) / sum(f R lambda) over the bins (all 5 nm wide: the weights cancel).
    weight = rad.band_response * (intensity[2] * wl)[None, :]
    mean_t = (weight * t[2]).sum(axis=1) / weight.sum(axis=1)
    assert diff[2] == pytest.approx(-2.5 * np.log10(mean_t), abs=ROUND_OFF_MAG)
    # the standard magnitude is the exo one at 1000 km
    expected_std = rad.ab_magnitude_exo - 5 * np.log10(range_m / 1e6)[:, None]
    np.testing.assert_allclose(rad.ab_magnitude_standard, expected_std, atol=ROUND_OFF_MAG)
    # the V band of the scenario and the Vega V differ by the 0.02 offset only
    assert rad.vega_v_magnitude is not None and rad.vega_v_magnitude_standard is not None
    np.testing.assert_allclose(
        rad.vega_v_magnitude, rad.ab_magnitude[:, 1] - 0.02, atol=ROUND_OFF_MAG
    )
    np.testing.assert_allclose(
        rad.vega_v_magnitude_standard, expected_std[:, 1] - 0.02, atol=ROUND_OFF_MAG
    )
