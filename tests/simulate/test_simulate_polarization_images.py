"""Stokes Q, U of the saved images (``render.polarization``, single mode): they integrate to
the intensity's Q, U, a one-material microfacet sphere has the Fresnel DoLP of the half-phase
angle in every lit pixel, a Lambertian target's images are unpolarised, and the images
figure draws a DoLP panel."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
import yaml

from speclight.plot.images import image_dolp, images_figure
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate
from speclight.target.optical_constants import refractive_index

SAVED = [1, 3]


def _simulate(tmp_path, material: dict, polarization: bool = True) -> xr.Dataset:
    data = yaml.safe_load(example_text("calsphere"))
    data["time"] = {"start": "2020-02-29T21:16:00Z", "stop": "2020-02-29T21:16:20Z", "step_s": 5}
    data["spectrum"] = {"min_nm": 400, "max_nm": 900, "step_nm": 20}
    data["instrument"]["bands"] = data["instrument"]["bands"][:4]  # B, G, R, V
    data["target"]["materials"]["body"] = material
    data["render"].update(
        {"resolution_px": 24, "polarization": polarization, "save_images_at": SAVED}
    )
    return simulate(parse_scenario(yaml.safe_dump(data), base_dir=tmp_path)).dataset


GGX_AL = {"bsdf": "ggx", "roughness": 0.3, "reflectance": {"conductor": "Al"}}


@pytest.fixture(scope="module")
def ggx(tmp_path_factory: pytest.TempPathFactory) -> xr.Dataset:
    return _simulate(tmp_path_factory.mktemp("polimg"), GGX_AL)


def test_image_stokes_integrate_to_the_intensity_stokes(ggx: xr.Dataset) -> None:
    # Radiant intensity of an orthographic view = sum of radiance x pixel area, for each
    # Stokes component alike (as test_saved_images_integrate_to_the_intensity for I).
    for name in ("image_radiance_q", "image_radiance_u"):
        assert ggx[name].dims == ("image_time", "y", "x", "wavelength")
        assert ggx[name].attrs["units"] == "W m-2 sr-1 nm-1"
    pixel_area = ggx["image_pixel_size"].values[:, None] ** 2
    lit = np.isfinite(ggx["dolp"].values[SAVED]).all(axis=1)
    assert lit.all()  # both saved epochs are sunlit: the identity is not vacuous
    for image, total in (("image_radiance_q", "intensity_q"), ("image_radiance_u", "intensity_u")):
        summed = ggx[image].sum(dim=("y", "x")).values * pixel_area
        expected = ggx[total].values[SAVED]
        np.testing.assert_allclose(summed, expected, rtol=1e-5, atol=1e-6 * np.abs(expected).max())
    # not vacuous: the sphere's light is polarised (both Q and U are non-zero somewhere)
    assert np.abs(ggx["intensity_q"].values[SAVED]).max() > 0
    assert np.abs(ggx["intensity_u"].values[SAVED]).max() > 0


def _fresnel_dolp(cos_i: float, eta: np.ndarray) -> np.ndarray:
    """(R_s - R_p) / (R_s + R_p) from the Fresnel equations for a medium of complex index
    ``eta`` = n + ik seen from vacuum (Born & Wolf, Principles of Optics, sec. 1.5.2 and
    13.2; complex index for absorbing media)."""
    sin2 = 1.0 - cos_i**2
    root = np.sqrt(eta.astype(complex) ** 2 - sin2)
    r_s = np.abs((cos_i - root) / (cos_i + root)) ** 2
    r_p = np.abs((eta**2 * cos_i - root) / (eta**2 * cos_i + root)) ** 2
    return (r_s - r_p) / (r_s + r_p)


def test_microfacet_sphere_has_the_fresnel_dolp_of_the_half_phase_angle_everywhere(
    ggx: xr.Dataset,
) -> None:
    # Single scattering off a microfacet surface: every reflecting facet's normal is the half
    # vector, so its incidence angle is half the phase angle in every pixel and the pixel's
    # DoLP is the Fresnel ratio there, whatever the pixel's D G weights.
    wl = ggx["wavelength"].values
    eta = refractive_index("Al", wl)  # the material's n, k data (the input, not the model)
    for k, e in enumerate(SAVED):
        half_phase = np.radians(float(ggx["phase_angle"].values[e])) / 2.0
        expected = np.abs(_fresnel_dolp(np.cos(half_phase), eta))
        i = ggx["image_radiance"].values[k].astype(float)
        q = ggx["image_radiance_q"].values[k].astype(float)
        u = ggx["image_radiance_u"].values[k].astype(float)
        lit = i.sum(axis=-1) > 1e-6 * i.sum(axis=-1).max()
        assert lit.sum() > 20  # many lit pixels at 24 x 24
        dolp = np.hypot(q[lit], u[lit]) / i[lit]
        np.testing.assert_allclose(dolp, np.broadcast_to(expected, dolp.shape), rtol=1e-4)
        assert expected.min() > 1e-3  # the check is not vacuous


def test_images_figure_has_a_dolp_panel(ggx: xr.Dataset) -> None:
    import matplotlib.pyplot as plt

    fig = images_figure(ggx, None)
    titles = [ax.get_title() for ax in fig.axes]
    assert sum("degree of linear polarisation" in t for t in titles) == len(SAVED)
    plt.close(fig)
    # the panel's values: one DoLP over the whole grid, the same in every lit pixel (the
    # Fresnel ratio varies with wavelength, but each pixel weighs wavelengths alike up to a
    # constant factor); NaN off the target
    d = image_dolp(ggx, 0, "V")
    on = np.isfinite(d)
    assert on.sum() > 20 and not on.all()
    np.testing.assert_allclose(d[on], np.median(d[on]), rtol=1e-4)


def test_lambertian_images_are_unpolarised_and_without_polarization_absent(tmp_path) -> None:
    (tmp_path / "a").mkdir(), (tmp_path / "b").mkdir()
    lamb = _simulate(tmp_path / "a", {"bsdf": "lambertian", "reflectance": 0.5})
    assert np.abs(lamb["image_radiance"].values).max() > 0
    for name in ("image_radiance_q", "image_radiance_u"):
        np.testing.assert_array_equal(lamb[name].values, 0.0)
    plain = _simulate(tmp_path / "b", GGX_AL, polarization=False)
    assert "image_radiance" in plain
    assert "image_radiance_q" not in plain and "image_radiance_u" not in plain
