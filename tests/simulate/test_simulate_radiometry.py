"""End-to-end: scenario -> intensity -> count rate, against closed forms computed here."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from speclight.errors import InputError
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate

H_C_J_M = 6.62607015e-34 * 2.99792458e8  # CODATA 2018 exact constants


def _calsphere(**changes: object) -> str:
    data = yaml.safe_load(example_text("calsphere"))
    data["time"] = {"start": "2020-02-29T21:15:30Z", "stop": "2020-02-29T21:19:30Z", "step_s": 30}
    data.update(changes)
    return yaml.safe_dump(data, sort_keys=False)


def lambert_sphere_intensity(rho: float, e: np.ndarray, r_m: float, alpha: np.ndarray):
    """Russell (1916), ApJ 43, 173: I = (2/(3 pi)) rho E R^2 [sin a + (pi - a) cos a]."""
    a = alpha[:, None]
    return 2 / (3 * np.pi) * rho * e * r_m**2 * (np.sin(a) + (np.pi - a) * np.cos(a))


@pytest.fixture(scope="module")
def plain_pass():
    """Calsphere 4A as a Lambertian sphere, no atmosphere, one Gaussian band, QE 1."""
    instrument = {
        "exposure_s": 1.0,
        "bands": [{"name": "G-600/40", "gaussian": {"center_nm": 600, "sigma_nm": 40}}],
    }
    text = _calsphere(atmosphere={"model": "none"}, instrument=instrument)
    return simulate(parse_scenario(text)).dataset


def test_intensity_follows_lambert_sphere_phase_law(plain_pass) -> None:
    ds = plain_pass
    lit = (ds["flags"].values == 0) & (ds["sunlit"].values == 1)
    assert lit.sum() >= 5
    alpha = np.radians(ds["phase_angle"].values[lit])
    expected = lambert_sphere_intensity(0.9, ds["solar_irradiance"].values[lit], 0.18, alpha)
    # 0.5 %: the render-stage accuracy of the Lambert sphere (issue 3) at these phases
    np.testing.assert_allclose(ds["intensity"].values[lit], expected, rtol=5e-3)


def test_count_rate_is_the_photon_integral_over_the_band(plain_pass) -> None:
    ds = plain_pass
    lit = (ds["flags"].values == 0) & (ds["sunlit"].values == 1)
    wl_nm = ds["wavelength"].values
    area_m2 = np.pi * 0.43**2 / 4
    range_m = ds["range"].values[lit]
    # Independent: trapezoid of I A/r^2 * lambda/(hc) * Gaussian(600, 40) over wavelength.
    gauss = np.exp(-0.5 * ((wl_nm - 600) / 40) ** 2)
    photons = ds["intensity"].values[lit] * area_m2 / range_m[:, None] ** 2 * wl_nm * 1e-9
    expected = np.trapezoid(photons / H_C_J_M * gauss, wl_nm, axis=1)
    # bin averages vs point samples of a 40 nm Gaussian on a 5 nm grid: < 0.1 %
    np.testing.assert_allclose(ds["count_rate"].values[lit, 0], expected, rtol=1e-3)


def test_unlit_epochs_are_zero_and_unobservable_are_nan(plain_pass) -> None:
    ds = plain_pass
    flags = ds["flags"].values
    unobservable = (flags & 3) > 0
    shadow = ~unobservable & (ds["sunlit"].values == 0)
    assert np.all(np.isnan(ds["intensity"].values[unobservable]))
    assert np.all(ds["intensity"].values[shadow] == 0)
    assert np.all(ds["count_rate"].values[shadow] == 0)


def test_atmosphere_reduces_flux_more_in_the_blue() -> None:
    ds = simulate(parse_scenario(_calsphere())).dataset
    ok = (ds["flags"].values & 3) == 0
    t = ds["transmission"].values[ok]
    wl = ds["wavelength"].values
    assert np.all((t > 0) & (t < 1))
    # Rayleigh scattering grows as lambda^-4: the clear-sky transmission rises from 400 to 800 nm
    assert np.all(t[:, wl == 400] < t[:, wl == 800])
    assert np.all(np.isnan(ds["transmission"].values[~ok]))


def test_unknown_filter_name_is_input_error_naming_the_field() -> None:
    instrument = {"bands": [{"name": "V", "filter": "bessel-V"}]}
    with pytest.raises(InputError, match=r"bessell-V"):
        simulate(parse_scenario(_calsphere(instrument=instrument)))


def test_band_outside_the_wavelength_grid_is_input_error() -> None:
    instrument = {"bands": [{"name": "G-1500/20", "gaussian": {"center_nm": 1500, "sigma_nm": 20}}]}
    with pytest.raises(InputError, match=r"G-1500/20"):
        simulate(parse_scenario(_calsphere(instrument=instrument)))


def test_saved_images_integrate_to_the_intensity(tmp_path) -> None:
    # Radiant intensity of an orthographic view = sum of radiance x pixel area
    # (definition of radiant intensity from radiance over the projected area).
    text = _calsphere(render={"resolution_px": 64, "save_images_at": [3, 5]})
    ds = simulate(parse_scenario(text)).dataset
    assert list(ds["image_time"].values) == list(ds["time"].values[[3, 5]])
    pixel_area = ds["image_pixel_size"].values[:, None] ** 2
    summed = ds["image_radiance"].sum(dim=("y", "x")).values * pixel_area
    np.testing.assert_allclose(summed, ds["intensity"].values[[3, 5]], rtol=1e-5)
    assert ds["image_part"].attrs["flag_meanings"] == "body"  # the sphere's one part
    np.testing.assert_array_equal(np.isfinite(ds["image_depth"].values), ds["image_part"] == 0)
    depth = ds["image_depth"].values
    on_target = np.isfinite(depth)
    # the sphere's visible surface lies within one radius in front of its centre
    assert np.all((depth[on_target] >= -0.18 - 1e-6) & (depth[on_target] <= 1e-6))
