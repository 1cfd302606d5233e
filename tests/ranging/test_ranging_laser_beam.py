"""Laser beam footprint and line shape against closed forms and conservation of energy."""

import numpy as np
import pytest
from scipy import integrate

from speclight.errors import InputError
from speclight.illumination import laser as lz


def test_gaussian_beam_carries_the_laser_power():
    # Conservation: the irradiance integrated over the plane at the target is P
    # (Saleh & Teich 2007, eq. 3.1-9 normalisation of the Gaussian beam).
    power, theta, rng = 7.0, 20 * lz.ARCSEC_RAD, 1.2e6
    w = rng * theta / 2

    def ring(r: float) -> float:
        return 2 * np.pi * r * float(lz.beam_irradiance_W_m2(power, theta, rng, r / rng)[()])

    total, _ = integrate.quad(ring, 0.0, 6 * w)
    np.testing.assert_allclose(total, power, rtol=1e-9)
    # on-axis peak 2P/(pi w²) = P G_t/(4 pi R²), G_t = 8/theta_t² (Degnan 1993 eq. 2.4)
    peak = lz.beam_irradiance_W_m2(power, theta, np.array([rng]))[0]
    np.testing.assert_allclose(peak, power * 8 / (theta / 2) ** 2 / (4 * np.pi * rng**2))
    # the 1/e² radius is w: exp(-2) of the peak there
    edge = lz.beam_irradiance_W_m2(power, theta, np.array([rng]), w / rng)[0]
    np.testing.assert_allclose(edge / peak, np.exp(-2.0))


def test_tophat_beam_carries_the_laser_power():
    power, theta, rng = 3.0, 10 * lz.ARCSEC_RAD, 8e5
    e = lz.beam_irradiance_W_m2(power, theta, np.array([rng]), profile="tophat")[0]
    np.testing.assert_allclose(e * np.pi * (rng * theta / 2) ** 2, power)


def test_gaussian_line_is_normalised_and_centred():
    wl = np.arange(1000.0, 1130.0, 0.5)
    shape = lz.gaussian_line_per_nm(wl, 1064.2, 3.0)
    np.testing.assert_allclose(lz.line_fraction_in_grid(shape, wl), 1.0, rtol=1e-12)
    mean = np.sum(shape * wl * 0.5)
    # bin-averaged centroid of a symmetric line: within 1e-3 of a 0.5 nm bin
    np.testing.assert_allclose(mean, 1064.2, atol=5e-4)
    var = np.sum(shape * (wl - mean) ** 2 * 0.5)
    sigma = 3.0 / (2 * np.sqrt(2 * np.log(2)))
    # binning adds width²/12 to the variance (Sheppard's correction)
    np.testing.assert_allclose(var, sigma**2 + 0.5**2 / 12, rtol=1e-3)


def test_narrow_line_falls_in_one_bin():
    wl = np.arange(500.0, 560.0, 5.0)
    shape = lz.gaussian_line_per_nm(wl, 531.0, 0.1)
    assert np.count_nonzero(shape > 1e-12) == 1
    np.testing.assert_allclose(shape.max() * 5.0, 1.0)


def test_table_line_is_normalised(tmp_path):
    f = tmp_path / "line.csv"
    f.write_text("wavelength_nm,value\n528,0\n530,5\n532,10\n534,5\n536,0\n")
    x, y = lz.read_laser_spectrum(f)
    wl = np.arange(500.0, 560.0, 1.0)
    shape = lz.table_line_per_nm(wl, x, y)
    np.testing.assert_allclose(np.sum(shape), 1.0, rtol=1e-12)
    np.testing.assert_allclose(np.sum(shape * wl), 532.0, rtol=1e-12)  # symmetric triangle


@pytest.mark.parametrize("power", [0.0, -5.0, float("nan")])
def test_power_must_be_positive(power):
    with pytest.raises(InputError, match="power_w"):
        lz.check_power_w(power)


def test_divergence_in_radians_or_degrees_is_refused_with_the_conversion():
    with pytest.raises(InputError, match=r"radians or degrees.*arcsec") as err:
        lz.check_divergence_arcsec(4.85e-5, 532.0)  # 10 arcsec written in radians
    assert "10 arcsec" in str(err.value) or "10.0" in str(err.value)
    with pytest.raises(InputError, match="radians or degrees"):
        lz.check_divergence_arcsec(0.0028, 532.0)  # 10 arcsec written in degrees
    with pytest.raises(InputError, match="microradians"):
        lz.check_divergence_arcsec(50000.0, 532.0)
    with pytest.raises(InputError, match="> 0"):
        lz.check_divergence_arcsec(0.0, 532.0)
    # a real SLR beam is accepted and converted: 10 arcsec = 48.48 urad
    np.testing.assert_allclose(lz.check_divergence_arcsec(10.0, 532.0), 4.8481368e-5)


def test_pulse_energy():
    np.testing.assert_allclose(lz.pulse_energy_J(10.0, 100.0), 0.1)
    with pytest.raises(InputError, match="repetition_rate_hz"):
        lz.pulse_energy_J(10.0, 0.0)
