"""Airmass and site pressure against published tables."""

from __future__ import annotations

import numpy as np
import pytest

from speclight.atmosphere import airmass, pressure_from_altitude
from speclight.errors import InputError

# Kasten & Young 1989 (Appl. Opt. 28, 4735), Table 1: rigorous airmass of the ISO standard
# atmosphere at the horizon, m(0 deg) = 38.0868. Their formula is stated to be within
# 0.5 % of the rigorous values at all elevations.
KY_HORIZON = 38.0868
KY_FORMULA_ACCURACY = 0.005


def test_airmass_at_horizon_matches_kasten_young_table() -> None:
    m = airmass(np.array([1e-9]))[0]
    assert m == pytest.approx(KY_HORIZON, rel=KY_FORMULA_ACCURACY)


def test_airmass_tends_to_plane_parallel_secant_high_up() -> None:
    # Above 30 deg the Earth's curvature and refraction change the airmass by < 0.5 %
    # (Kasten & Young 1989, Table 1 vs 1/sin h), so the secant law is the reference.
    el = np.array([30.0, 45.0, 60.0, 90.0])
    assert np.allclose(airmass(el), 1 / np.sin(np.radians(el)), rtol=5e-3)


def test_airmass_nan_at_and_below_horizon() -> None:
    m = airmass(np.array([0.0, -3.0, np.nan, 10.0]))
    assert np.isnan(m[:3]).all() and np.isfinite(m[3])


@pytest.mark.parametrize(
    ("altitude_m", "pressure_pa"),
    # U.S. Standard Atmosphere 1976 (NOAA-S/T 76-1562), Table I, geopotential altitude.
    [(0.0, 101325.0), (1000.0, 89874.6), (2000.0, 79495.2), (5000.0, 54019.9)],
)
def test_pressure_matches_us_standard_atmosphere(altitude_m: float, pressure_pa: float) -> None:
    # 1e-4: the table's 6 significant digits and the gas-constant convention.
    assert pressure_from_altitude(altitude_m) == pytest.approx(pressure_pa, rel=1e-4)


def test_pressure_rejects_altitude_outside_troposphere() -> None:
    with pytest.raises(InputError, match=r"observer\.altitude_m"):
        pressure_from_altitude(20000.0)


def test_airmass_equals_the_closed_form_it_replaced() -> None:
    # The Kasten & Young 1989 formula as speclight wrote it before it used pvlib (eq. 3 of
    # the paper): the switch to pvlib must not change a result.
    el = np.array([0.5, 2.0, 5.0, 10.0, 20.0, 45.0, 89.0, 90.0])
    old = 1.0 / (np.sin(np.radians(el)) + 0.50572 * (el + 6.07995) ** -1.6364)
    assert np.allclose(airmass(el), old, rtol=1e-12, atol=0.0)


def test_pressure_equals_the_barometric_formula_it_replaced() -> None:
    # The U.S. Standard Atmosphere 1976 eq. 33a with its constants (g0 = 9.80665 m s-2,
    # M = 0.0289644 kg mol-1, R* = 8.31432 J mol-1 K-1), as speclight computed it before.
    # pvlib's alt2pres writes the same law with rounded constants (R = 287.053 J kg-1 K-1,
    # exponent 1/0.1902632): 3e-5 apart at 10.5 km, far below the 1e-4 of the table test.
    for h in (-400.0, 0.0, 1500.0, 4200.0, 10500.0):
        old = 101325.0 * (1 - 0.0065 * h / 288.15) ** (9.80665 * 0.0289644 / (8.31432 * 0.0065))
        assert pressure_from_altitude(h) == pytest.approx(old, rel=5e-5)
