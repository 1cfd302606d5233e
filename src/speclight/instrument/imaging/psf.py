"""Point-spread functions with GalSim: seeing, diffraction, defocus, jitter.

The PSF is the convolution of

* the seeing disk: a Moffat profile (Moffat 1969, A&A 3, 455; beta = 4.765 fits Kolmogorov
  turbulence, Trujillo et al. 2001, MNRAS 328, 977) or a Gaussian, of the given FWHM;
* the telescope's diffraction: the Airy pattern of a circular aperture with a central
  obstruction (Born & Wolf, *Principles of Optics*, 8.5.2; the obscured case: Mahajan 1986,
  JOSA A 3, 470, doi:10.1364/JOSAA.3.000470), or with defocus GalSim's ``OpticalPSF``
  (the pupil's Fourier transform with the Zernike Z4 aberration, Noll 1976);
* pointing jitter: a Gaussian of the given rms per axis.

GalSim (Rowe et al. 2015, Astronomy and Computing 10, 121, doi:10.1016/j.ascom.2015.02.002)
draws the profile integrated over the pixels of a fine grid; :func:`psf_kernel` crops it to
the radius holding :data:`KERNEL_ENERGY` of the light. Diffraction is evaluated at the
band's mean photon wavelength (one monochromatic Airy pattern per band).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from speclight.engine_packages import require_engine
from speclight.errors import InputError

#: Arcseconds per radian.
ARCSEC_PER_RAD = 180.0 / np.pi * 3600.0
#: Fraction of the PSF's light the kernel keeps: the rest, in the far wings of the Airy
#: pattern (1 - EE ~ 2 / (pi v) at v = pi D theta / lambda; Born & Wolf 8.5.2), is dropped.
KERNEL_ENERGY = 0.998
#: Largest kernel half-width [fine pixels]: a 2049 x 2049 kernel; a PSF wider than that on
#: the fine grid keeps less than KERNEL_ENERGY (reported in the frame's truth).
MAX_KERNEL_HALF_PX = 1024


@dataclass(frozen=True)
class PsfSpec:
    """What makes the PSF (plain values; the scenario's ``instrument.imaging.psf``).

    Attributes
    ----------
    seeing_profile
        ``moffat``, ``gaussian`` or ``None`` (no atmosphere).
    seeing_fwhm_arcsec
        FWHM of the seeing disk [arcsec].
    moffat_beta
        Moffat's beta (wing slope).
    diffraction
        Include the aperture's diffraction.
    aperture_diameter_m, obstruction_diameter_m
        Telescope aperture and central obstruction [m].
    defocus_waves
        Zernike Z4 (Noll) coefficient [waves rms].
    jitter_rms_arcsec
        Pointing jitter per axis [arcsec rms].
    """

    seeing_profile: Literal["moffat", "gaussian"] | None = "moffat"
    seeing_fwhm_arcsec: float = 2.0
    moffat_beta: float = 4.765
    diffraction: bool = True
    aperture_diameter_m: float = 0.43
    obstruction_diameter_m: float = 0.0
    defocus_waves: float = 0.0
    jitter_rms_arcsec: float = 0.0


def _galsim() -> Any:
    require_engine("galsim", "instrument.imaging.psf", "speclight frames (the PSF)")
    import galsim

    return galsim


def psf_profile(spec: PsfSpec, wavelength_nm: float) -> Any:
    """The PSF as a GalSim profile in arcseconds (flux 1).

    Parameters
    ----------
    spec
        The PSF's parts.
    wavelength_nm
        Wavelength of the diffraction pattern [nm] (the band's mean photon wavelength).

    Returns
    -------
    galsim.GSObject
    """
    galsim = _galsim()
    parts = []
    if spec.seeing_profile == "moffat":
        parts.append(galsim.Moffat(beta=spec.moffat_beta, fwhm=spec.seeing_fwhm_arcsec))
    elif spec.seeing_profile == "gaussian":
        parts.append(galsim.Gaussian(fwhm=spec.seeing_fwhm_arcsec))
    if spec.diffraction:
        if not (np.isfinite(wavelength_nm) and wavelength_nm > 0):
            raise InputError(f"wavelength_nm = {wavelength_nm!r} must be > 0", field="band")
        obscuration = spec.obstruction_diameter_m / spec.aperture_diameter_m
        if spec.defocus_waves != 0.0:
            parts.append(
                galsim.OpticalPSF(
                    lam=wavelength_nm,
                    diam=spec.aperture_diameter_m,
                    defocus=spec.defocus_waves,
                    obscuration=obscuration,
                    scale_unit=galsim.arcsec,
                )
            )
        else:
            parts.append(
                galsim.Airy(
                    lam=wavelength_nm,
                    diam=spec.aperture_diameter_m,
                    obscuration=obscuration,
                    scale_unit=galsim.arcsec,
                )
            )
    if spec.jitter_rms_arcsec > 0:
        parts.append(galsim.Gaussian(sigma=spec.jitter_rms_arcsec))
    if not parts:
        raise InputError(
            "the PSF is empty: give seeing, diffraction or jitter", field="instrument.imaging.psf"
        )
    return parts[0] if len(parts) == 1 else galsim.Convolve(parts)


def reach_arcsec(spec: PsfSpec, wavelength_nm: float) -> float:
    """Radius that holds all but 1e-3 of the light of each part, summed [arcsec].

    Moffat: (1 + (r/alpha)^2)^(1 - beta) = 1e-3; Gaussian: 3.7 sigma; Airy:
    1 - EE ~ 2 / (pi v) (Born & Wolf 8.5.2); defocus: the geometric blur radius of the Z4
    wavefront, 8 sqrt(3) |a| lambda / D.
    """
    left = 1e-3
    reach = 0.0
    if spec.seeing_profile == "moffat":
        beta = spec.moffat_beta
        alpha = spec.seeing_fwhm_arcsec / (2.0 * np.sqrt(2.0 ** (1.0 / beta) - 1.0))
        reach += alpha * np.sqrt(left ** (1.0 / (1.0 - beta)) - 1.0)
    elif spec.seeing_profile == "gaussian":
        reach += spec.seeing_fwhm_arcsec / 2.3548 * np.sqrt(-2.0 * np.log(left))
    if spec.diffraction:
        lam_over_d = wavelength_nm * 1e-9 / spec.aperture_diameter_m * ARCSEC_PER_RAD
        reach += 2.0 / (np.pi * left) / np.pi * lam_over_d
        reach += 8.0 * np.sqrt(3.0) * abs(spec.defocus_waves) * lam_over_d
    reach += np.sqrt(-2.0 * np.log(left)) * spec.jitter_rms_arcsec
    return float(reach)


def fwhm_arcsec(spec: PsfSpec, wavelength_nm: float) -> float:
    """An estimate of the PSF's FWHM [arcsec]: the parts' FWHMs added in quadrature
    (Airy: 1.029 lambda / D, Born & Wolf 8.5.2)."""
    squares = 0.0
    if spec.seeing_profile is not None:
        squares += spec.seeing_fwhm_arcsec**2
    if spec.diffraction:
        squares += (1.029 * wavelength_nm * 1e-9 / spec.aperture_diameter_m * ARCSEC_PER_RAD) ** 2
    squares += (2.3548 * spec.jitter_rms_arcsec) ** 2
    return float(np.sqrt(squares))


def psf_kernel(
    spec: PsfSpec, wavelength_nm: float, fine_scale_arcsec: float
) -> NDArray[np.float64]:
    """The PSF drawn on the fine grid and cropped to :data:`KERNEL_ENERGY` of its light.

    Each value is the light falling in that fine pixel (GalSim's ``drawImage`` with the
    pixel's response); the kernel is square with an odd side and its centre at the middle
    pixel's centre. Its sum is the light it holds (at least ``KERNEL_ENERGY`` unless the
    PSF is wider than :data:`MAX_KERNEL_HALF_PX`; nothing is renormalised).

    Parameters
    ----------
    spec
        The PSF's parts.
    wavelength_nm
        Diffraction wavelength [nm].
    fine_scale_arcsec
        Fine pixel size [arcsec] (the detector's plate scale over the oversampling).

    Returns
    -------
    numpy.ndarray
        (K, K), K odd [fraction of the light per fine pixel].
    """
    if not (np.isfinite(fine_scale_arcsec) and fine_scale_arcsec > 0):
        raise InputError(f"fine_scale_arcsec = {fine_scale_arcsec!r} must be > 0")
    profile = psf_profile(spec, wavelength_nm)
    half = int(np.ceil(reach_arcsec(spec, wavelength_nm) / fine_scale_arcsec)) + 2
    half = min(half, MAX_KERNEL_HALF_PX)
    size = 2 * half + 1
    image = profile.drawImage(
        nx=size, ny=size, scale=fine_scale_arcsec, method="auto", dtype=np.float64
    ).array
    y, x = np.indices(image.shape)
    radius = np.maximum(np.abs(x - half), np.abs(y - half))  # square rings: crop is square
    ring = np.bincount(radius.ravel(), weights=image.ravel())
    enclosed = np.cumsum(ring)
    keep = int(np.searchsorted(enclosed, KERNEL_ENERGY))
    keep = min(max(keep, 1), half)
    return np.ascontiguousarray(image[half - keep : half + keep + 1, half - keep : half + keep + 1])


def shape_kernel(
    offsets_px: NDArray[np.float64], weights: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A resolved target's light on the fine grid, centred on its centre of mass.

    Parameters
    ----------
    offsets_px
        (P, 2) offsets (x, y) of the target's image pixels from its centre of mass, in fine
        pixels.
    weights
        (P,) light of each image pixel (any scale).

    Returns
    -------
    kernel, centroid
        (K, K) kernel (K odd, sum 1) with the centre of mass at its middle pixel, and the
        light's centroid offset from the centre of mass (x, y) [fine pixels].
    """
    from speclight.instrument.imaging.streak_raster import splat_bilinear

    w = np.asarray(weights, dtype=np.float64)
    total = float(w.sum())
    if not (total > 0):
        raise InputError("the target's image holds no light", field="image_radiance")
    off = np.asarray(offsets_px, dtype=np.float64)
    half = int(np.ceil(np.max(np.abs(off)))) + 1
    size = 2 * half + 1
    kernel = splat_bilinear((size, size), off[:, 0] + half, off[:, 1] + half, w / total)
    centroid = (w[:, None] * off).sum(axis=0) / total
    return kernel, centroid
