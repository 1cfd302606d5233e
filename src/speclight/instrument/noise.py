"""Simulated measurements: sky background, dark current, shot and read noise."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError
from speclight.instrument.photometry import ab_reference_W_m2_nm, photon_kernel

#: Largest mean electron count drawn from the Poisson distribution; above it the count is
#: drawn from its normal approximation N(lam, lam), whose largest CDF error against Poisson
#: (Edgeworth: skewness lam**-0.5 / (6 sqrt(2 pi))) is below 7e-8 here. numpy's generator
#: refuses lam above about 9.2e18 (its int64 range), and its variance drifts well before:
#: measured with numpy 2.4, 4e5 draws at a fixed seed, the sample variance is within 3
#: standard errors of lam up to lam = 1e14 and 42 above it at 3e14; 1e12 keeps two decades
#: below that.
POISSON_MAX_MEAN = 1e12


def sky_count_rate_per_s(
    sky_background_mag_arcsec2: ArrayLike,
    aperture_area_m2: float,
    wavelength_nm: ArrayLike,
    optics: ArrayLike,
    qe: ArrayLike,
    band_response: ArrayLike,
    *,
    background_aperture_arcsec2: float | None = None,
    background_aperture_radius_arcsec: float | None = None,
) -> NDArray[np.float64]:
    """Photo-electron rate of the sky inside the photometric aperture, per band.

    The sky's surface brightness :math:`\\mu_b` [AB mag arcsec-2] in band b is taken as a
    spectrum flat in f_nu across the band; over a solid angle :math:`\\Omega` [arcsec2] it
    is a source of AB magnitude :math:`\\mu_b - 2.5 \\log_{10} \\Omega`, sent through the
    same chain (aperture, optics, QE, band) as the target.

    Parameters
    ----------
    sky_background_mag_arcsec2
        Surface brightness per band (B,) or one value for all [AB mag arcsec-2]
        (dark site ~21-22 in V, city ~18).
    aperture_area_m2
        Telescope collecting area [m2].
    wavelength_nm, optics, qe, band_response
        As for :func:`~speclight.instrument.count_rate_per_s`.
    background_aperture_arcsec2, background_aperture_radius_arcsec
        Solid angle of the photometric aperture on the sky [arcsec2], or its radius
        [arcsec] (area pi r^2); exactly one.

    Returns
    -------
    numpy.ndarray
        Sky photo-electron rate (B,) [s-1].
    """
    if (background_aperture_arcsec2 is None) == (background_aperture_radius_arcsec is None):
        raise InputError(
            "give exactly one of background_aperture_arcsec2 or background_aperture_radius_arcsec",
            field="instrument.background_aperture_arcsec2",
        )
    if background_aperture_radius_arcsec is not None:
        omega = np.pi * float(background_aperture_radius_arcsec) ** 2
        name = "background_aperture_radius_arcsec"
    else:
        omega = float(background_aperture_arcsec2)  # type: ignore[arg-type]
        name = "background_aperture_arcsec2"
    if not (np.isfinite(omega) and omega > 0):
        raise InputError(f"{name} must be > 0", field=f"instrument.{name}")
    kernel = photon_kernel(wavelength_nm, optics, qe, band_response)
    mu = np.broadcast_to(np.asarray(sky_background_mag_arcsec2, dtype=np.float64), kernel.shape[:1])
    if not np.all(np.isfinite(mu)):
        raise InputError(
            "sky_background_mag_arcsec2 must be finite (one per band or one for all)",
            field="instrument.sky_background_mag_arcsec2",
        )
    ab0_rate = aperture_area_m2 * (kernel @ ab_reference_W_m2_nm(wavelength_nm))
    return ab0_rate * omega * 10.0 ** (-0.4 * mu)


def simulate_measurement(
    count_rate_per_s: ArrayLike,
    exposure_s: float,
    *,
    sky_count_rate_per_s: ArrayLike = 0.0,
    dark_current_e_per_s: float = 0.0,
    read_noise_e: float = 0.0,
    seed: int | None = None,
) -> NDArray[np.float64]:
    """One noisy, background-subtracted measurement of each count rate.

    Electrons collected in ``exposure_s``: Poisson with mean (S + B + D) t for signal S,
    sky B and dark D rates (normal with the same mean and variance above
    :data:`POISSON_MAX_MEAN`), plus Gaussian read noise of standard deviation sigma_r. The
    known mean background (B + D) t is subtracted and the result divided by t, so the
    measured rate is unbiased with variance ((S + B + D) t + sigma_r^2) / t^2.

    Parameters
    ----------
    count_rate_per_s
        Noiseless signal rate (N, B) [s-1], >= 0; NaN rows stay NaN.
    exposure_s
        Exposure time [s], > 0.
    sky_count_rate_per_s
        Sky rate in the aperture (B,) or scalar [s-1] (:func:`sky_count_rate_per_s`).
    dark_current_e_per_s
        Dark current summed over the aperture's pixels [e- s-1].
    read_noise_e
        Read noise of the whole aperture (pixel read noise x sqrt(pixels)) [e- rms].
    seed
        Seed of :func:`numpy.random.default_rng`.

    Returns
    -------
    numpy.ndarray
        Measured rate (N, B) [s-1] (may be negative for faint signals, as real
        background-subtracted photometry is).
    """
    rate = np.asarray(count_rate_per_s, dtype=np.float64)
    t = float(exposure_s)
    if not (np.isfinite(t) and t > 0):
        raise InputError(f"exposure_s = {exposure_s!r} must be > 0", field="instrument.exposure_s")
    for value, key in (
        (dark_current_e_per_s, "dark_current_e_per_s"),
        (read_noise_e, "read_noise_e"),
    ):
        if not (np.isfinite(value) and value >= 0):
            raise InputError(f"{key} = {value!r} must be >= 0", field=f"instrument.{key}")
    sky = np.broadcast_to(np.asarray(sky_count_rate_per_s, dtype=np.float64), rate.shape[-1:])
    if np.any(sky < 0) or np.any(rate[np.isfinite(rate)] < 0):
        raise InputError("count and sky rates must be >= 0", field="instrument")
    rng = np.random.default_rng(seed)
    ok = np.isfinite(rate)
    background = (sky + dark_current_e_per_s) * t  # (B,)
    mean = np.where(ok, rate * t + background, 0.0)
    large = mean > POISSON_MAX_MEAN
    counts = rng.poisson(np.where(large, 0.0, mean)).astype(np.float64)
    electrons = counts + rng.normal(0.0, read_noise_e, size=rate.shape)
    if np.any(large):  # drawn after the others, so that runs without large means are unchanged
        electrons[large] += rng.normal(mean[large], np.sqrt(mean[large]))
    return np.where(ok, (electrons - background) / t, np.nan)
