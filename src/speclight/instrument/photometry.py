"""Detected photo-electron rates and AB magnitudes per band.

Quadrature: every wavelength integral is a bin sum, sum_i f_i w_i, with w_i the widths of
bins whose edges lie half-way between samples (:func:`~speclight.wavelength_grid.bin_widths_nm`);
each sample is the mean over its bin (6S and the tables are band-averaged over exactly
these bins, Gaussian bands through the error function), so the bin sum is the integral of
that piecewise-constant spectrum. On the default 5 nm grid it differs from the trapezoid
rule only in the half-weights of the two end samples.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.constants import AB_ZERO_W_M2_HZ, C_M_S, H_J_S
from speclight.errors import InputError
from speclight.wavelength_grid import bin_widths_nm, check_wavelength_grid


def ab_reference_W_m2_nm(wavelength_nm: ArrayLike) -> NDArray[np.float64]:
    """Spectral irradiance of an AB = 0 source, f_nu c / lambda^2 [W m-2 nm-1]."""
    wl_m = np.asarray(wavelength_nm, dtype=np.float64) * 1e-9
    return AB_ZERO_W_M2_HZ * C_M_S / wl_m**2 * 1e-9


def _check(flux: NDArray, wl: NDArray, band: NDArray) -> None:
    if flux.ndim != 2 or flux.shape[1] != wl.size or band.ndim != 2 or band.shape[1] != wl.size:
        raise InputError(
            f"shapes must be spectral flux (N, L), wavelength (L,), band response (B, L); got "
            f"{flux.shape}, {wl.shape}, {band.shape}",
            field="instrument",
        )


def photon_kernel(
    wavelength_nm: ArrayLike, optics: ArrayLike, qe: ArrayLike, band_response: ArrayLike
) -> NDArray[np.float64]:
    """Electrons per joule per bin: band x optics x QE x lambda/(h c) x width (B, L) [nm J-1]."""
    wl = check_wavelength_grid(wavelength_nm)
    band = np.atleast_2d(np.asarray(band_response, dtype=np.float64))
    eff = np.asarray(optics, dtype=np.float64) * np.asarray(qe, dtype=np.float64)
    if eff.shape != wl.shape:
        raise InputError(
            f"optics and QE must be (L,) = {wl.shape}, got {eff.shape}", field="instrument"
        )
    return band * (eff * wl * 1e-9 / (H_J_S * C_M_S) * bin_widths_nm(wl))[None, :]


def count_rate_per_s(
    spectral_flux_W_nm: ArrayLike,
    wavelength_nm: ArrayLike,
    optics: ArrayLike,
    qe: ArrayLike,
    band_response: ArrayLike,
) -> NDArray[np.float64]:
    """Detected photo-electron rate per band.

    .. math:: \\dot N_b = \\int \\Phi_\\lambda\\,\\tau_{opt}\\,\\eta\\,R_b
              \\,\\frac{\\lambda}{hc}\\,d\\lambda

    evaluated as a bin sum (see module docstring).

    Parameters
    ----------
    spectral_flux_W_nm
        Power entering the aperture (N, L) [W nm-1].
    wavelength_nm
        Grid (L,) [nm].
    optics, qe
        Optics transmission and detector quantum efficiency (L,) [1].
    band_response
        Band responses (B, L) [1].

    Returns
    -------
    numpy.ndarray
        Photo-electron rate (N, B) [s-1]; NaN rows where the flux row has a NaN.
    """
    flux = np.asarray(spectral_flux_W_nm, dtype=np.float64)
    kernel = photon_kernel(wavelength_nm, optics, qe, band_response)
    _check(flux, np.asarray(wavelength_nm), kernel)
    # einsum's own loops, not BLAS: the same bits whatever the BLAS thread count (a Dask
    # worker runs BLAS on one thread), so distributed runs equal serial ones exactly
    return np.einsum("tl,bl->tb", flux, kernel)


def reflectance_factor_m2_sr(
    count_rate_per_s: ArrayLike,
    range_m: ArrayLike,
    aperture_area_m2: float,
    illumination_W_m2_nm: ArrayLike,
    wavelength_nm: ArrayLike,
    optics: ArrayLike,
    qe: ArrayLike,
    band_response: ArrayLike,
) -> NDArray[np.float64]:
    """Band signals made free of geometry and source: the reflectance factor per band.

    .. math:: F_j = \\dot N_j R^2 \\Big/ \\Big(A \\int E(\\lambda)\\,\tau_{opt}\\,\\eta\\,R_j
              \\,\frac{\\lambda}{hc}\\,d\\lambda\\Big)\\quad [\\mathrm{m^2\\,sr^{-1}}]

    (Nussbaum et al. 2022, eq. 5), with ``E`` the irradiance on the target times the
    transmission to the observer (the solar irradiance x sunlit fraction x T for the Sun).
    A target whose intensity is ``I = F E`` with a grey ``F`` (a constant spectral
    reflectance) has the same factor in every band: ``F`` itself.

    Parameters
    ----------
    count_rate_per_s
        (N, B) detected rates [s-1].
    range_m
        (N,) observer-target distance [m].
    aperture_area_m2
        Collecting area [m2].
    illumination_W_m2_nm
        (N, L) irradiance at the target times the transmission to the observer [W m-2 nm-1].
    wavelength_nm, optics, qe, band_response
        As for :func:`count_rate_per_s`.

    Returns
    -------
    numpy.ndarray
        (N, B) [m2 sr-1]; NaN where the band receives no light (shadow, below the horizon).
    """
    rate = np.asarray(count_rate_per_s, dtype=np.float64)
    illum = np.asarray(illumination_W_m2_nm, dtype=np.float64)
    kernel = photon_kernel(wavelength_nm, optics, qe, band_response)
    _check(illum, np.asarray(wavelength_nm), kernel)
    # per unit reflectance factor [s-1 m2]
    photons = aperture_area_m2 * np.einsum("tl,bl->tb", illum, kernel)
    r2 = np.asarray(range_m, dtype=np.float64)[:, None] ** 2
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.asarray(np.where(photons > 0, rate * r2 / photons, np.nan))


def ab_magnitude(
    spectral_flux_W_nm: ArrayLike,
    aperture_area_m2: float,
    wavelength_nm: ArrayLike,
    band_response: ArrayLike,
) -> NDArray[np.float64]:
    """AB magnitude of the in-band irradiance at the aperture (photon-counting weighting).

    .. math:: m_{AB} = -2.5 \\log_{10} \\frac{\\int f_\\lambda R \\lambda\\,d\\lambda}
              {\\int f^{AB}_\\lambda R \\lambda\\,d\\lambda},\\quad
              f^{AB}_\\lambda = 3631\\,\\mathrm{Jy}\\; c/\\lambda^2

    with the irradiance :math:`f_\\lambda` = spectral flux / aperture area, the same
    definition as speclite's ``FilterResponse.get_ab_magnitude`` (photon-weighted; band
    response only: optics and QE are not part of the magnitude system). Integrals are bin
    sums.

    Parameters
    ----------
    spectral_flux_W_nm
        (N, L) [W nm-1].
    aperture_area_m2
        [m2].
    wavelength_nm
        (L,) [nm].
    band_response
        (B, L) [1].

    Returns
    -------
    numpy.ndarray
        AB magnitude (N, B) [mag]; NaN where the in-band flux is <= 0 (e.g. an unlit
        target) or NaN.

    References
    ----------
    J. B. Oke and J. E. Gunn, ApJ 266, 713 (1983), doi:10.1086/160817; speclite
    documentation, "Filter response curves" (photon-weighted convolution).
    """
    if not (np.isfinite(aperture_area_m2) and aperture_area_m2 > 0):
        raise InputError(f"aperture area {aperture_area_m2!r} m2 must be > 0", field="telescope")
    wl = check_wavelength_grid(wavelength_nm)
    flux = np.asarray(spectral_flux_W_nm, dtype=np.float64)
    band = np.atleast_2d(np.asarray(band_response, dtype=np.float64))
    _check(flux, wl, band)
    weight = band * (wl * bin_widths_nm(wl))[None, :]  # (B, L)
    num = np.einsum("tl,bl->tb", flux / aperture_area_m2, weight)
    den = weight @ ab_reference_W_m2_nm(wl)
    with np.errstate(divide="ignore", invalid="ignore"):
        mag = -2.5 * np.log10(num / den[None, :])
    return np.where(num > 0, mag, np.nan)
