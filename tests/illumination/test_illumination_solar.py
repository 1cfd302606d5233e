"""Solar spectrum: published total and conservation of the integral by bin averaging."""

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.illumination import solar_irradiance_W_m2_nm, solar_table

# ASTM E490-00a(2019) states the solar constant of its table: 1366.1 W m-2 at 1 AU.
ASTM_E490_TOTAL_W_M2 = 1366.1
# The published total is given to 0.1 W m-2; allow half of that last digit.
PUBLISHED_ROUNDING_W_M2 = 0.05


def test_table_integrates_to_published_solar_constant():
    wl, e = solar_table()
    total = np.trapezoid(e, wl)
    assert abs(total - ASTM_E490_TOTAL_W_M2) < PUBLISHED_ROUNDING_W_M2


def test_bins_covering_the_table_conserve_the_total():
    wl, _ = solar_table()
    # Irregular bins covering the whole table: bin averages times widths must add up to the
    # total (the averaging is an exact integral of the interpolated table).
    edges = np.unique(np.concatenate([np.geomspace(wl[0], wl[-1], 400), [wl[0], wl[-1]]]))
    centres = 0.5 * (edges[1:] + edges[:-1])
    widths = np.diff(edges)
    e = solar_irradiance_W_m2_nm(centres, bin_width_nm=widths)
    assert abs(np.sum(e * widths) - ASTM_E490_TOTAL_W_M2) < PUBLISHED_ROUNDING_W_M2


def test_bin_average_equals_fine_quadrature_of_the_table():
    # Independent check on a 5 nm grid: integrate the interpolated table with a 0.01 nm
    # trapezoid rule inside each bin (relative quadrature error ~1e-7).
    wl_nm = np.arange(300.0, 1241.0, 5.0)
    e = solar_irradiance_W_m2_nm(wl_nm)
    t_wl, t_e = solar_table()
    for k in (0, 50, 188):
        x = np.linspace(wl_nm[k] - 2.5, wl_nm[k] + 2.5, 501)
        ref = np.trapezoid(np.interp(x, t_wl, t_e), x) / 5.0
        assert e[k] == pytest.approx(ref, rel=1e-6)


def test_inverse_square_distance_and_shapes():
    wl_nm = np.arange(300.0, 1241.0, 5.0)
    one = solar_irradiance_W_m2_nm(wl_nm)
    many = solar_irradiance_W_m2_nm(wl_nm, distance_au=np.array([1.0, 2.0, 0.5]))
    assert one.shape == (189,)
    assert many.shape == (3, 189)
    np.testing.assert_allclose(many, one[None, :] * np.array([[1.0], [0.25], [4.0]]))


def test_grid_outside_the_table_is_an_input_error():
    with pytest.raises(InputError, match="ASTM E490"):
        solar_irradiance_W_m2_nm(np.array([50.0, 60.0]))
    with pytest.raises(InputError, match="distance_au"):
        solar_irradiance_W_m2_nm(np.array([500.0, 505.0]), distance_au=-1.0)
