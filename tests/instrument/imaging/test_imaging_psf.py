"""PSF: the seeing's FWHM, and the diffraction pattern's encircled energy against the closed
forms for a circular and an annular aperture."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import j0, j1

from speclight.instrument.imaging.psf import PsfSpec, psf_kernel
from speclight.instrument.imaging.streak_raster import add_source

pytest.importorskip("galsim")
pytest.importorskip("photutils")
from astropy.modeling import fitting, models
from photutils.aperture import CircularAperture

ARCSEC_PER_RAD = 180.0 / np.pi * 3600.0


def _point_frame(spec: PsfSpec, pixel_arcsec: float, oversampling: int = 4) -> np.ndarray:
    kernel = psf_kernel(spec, 550.0, pixel_arcsec / oversampling)
    image = np.zeros((81, 81))
    add_source(image, np.array([40.3]), np.array([39.8]), np.array([1.0]), kernel, oversampling)
    return image


@pytest.mark.parametrize("profile", ["gaussian", "moffat"])
def test_point_source_fwhm_equals_the_seeing(profile) -> None:
    fwhm, pixel = 3.0, 0.3  # arcsec: 10 pixels across the FWHM
    spec = PsfSpec(seeing_profile=profile, seeing_fwhm_arcsec=fwhm, diffraction=False)
    image = _point_frame(spec, pixel)
    y, x = np.indices(image.shape)
    if profile == "gaussian":
        model = models.Gaussian2D(image.max(), 40, 40, 4, 4)
        fit = fitting.TRFLSQFitter()(model, x, y, image)
        got = 2.3548200450309493 * np.sqrt(fit.x_stddev.value * fit.y_stddev.value) * pixel
    else:
        model = models.Moffat2D(image.max(), 40, 40, 6.0, 4.765)
        fit = fitting.TRFLSQFitter()(model, x, y, image)
        got = fit.fwhm * pixel
    # the pixel (a box of width p) adds p^2 / 12 to the variance: the FWHM of a Gaussian
    # grows by 8 ln 2 p^2 / 12 in quadrature, 0.23 % here; the fit recovers the rest
    expected = np.sqrt(fwhm**2 + 8 * np.log(2) * pixel**2 / 12)
    assert got == pytest.approx(expected, rel=3e-3)


def _airy_ee(v: float, eps: float) -> float:
    """Encircled energy of an annular aperture's Airy pattern at v = pi D theta / lambda:
    Mahajan 1986 (JOSA A 3, 470, eq. 4; Born & Wolf 8.5.2 for eps = 0)."""
    core = 1.0 - j0(v) ** 2 - j1(v) ** 2
    if eps == 0:
        return core
    cross = quad(lambda t: j1(t) * j1(eps * t) / t, 0.0, v, limit=400)[0]
    inner = 1.0 - j0(eps * v) ** 2 - j1(eps * v) ** 2
    return (core + eps**2 * inner - 4.0 * eps * cross) / (1.0 - eps**2)


@pytest.mark.parametrize("obstruction_m", [0.0, 0.2])
def test_diffraction_encircled_energy_matches_the_closed_form(obstruction_m) -> None:
    diameter, wavelength = 0.5, 550.0
    lam_over_d = wavelength * 1e-9 / diameter * ARCSEC_PER_RAD
    spec = PsfSpec(
        seeing_profile=None,
        diffraction=True,
        aperture_diameter_m=diameter,
        obstruction_diameter_m=obstruction_m,
    )
    fine = lam_over_d / 20.0
    kernel = psf_kernel(spec, wavelength, fine)
    c = kernel.shape[0] // 2
    eps = obstruction_m / diameter
    for radius in (0.6, 1.22, 2.0, 5.0):  # in lambda / D
        got = CircularAperture((c, c), r=radius * 20.0).do_photometry(kernel)[0][0]
        want = _airy_ee(np.pi * radius, eps)
        # GalSim drops Fourier power below maxk_threshold = 1e-3 of the peak and folds the
        # pattern at folding_threshold = 5e-3 (its default GSParams); the fine pixels
        # (lambda / 20 D) shift the curve by < 1e-4
        assert got == pytest.approx(want, abs=1e-3)


def test_kernel_holds_the_chosen_fraction_of_the_light() -> None:
    spec = PsfSpec(seeing_profile="moffat", seeing_fwhm_arcsec=2.0, aperture_diameter_m=0.43)
    kernel = psf_kernel(spec, 550.0, 0.25)
    assert kernel.shape[0] % 2 == 1
    assert 0.998 <= kernel.sum() <= 1.0 + 1e-9
