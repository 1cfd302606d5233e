"""The laser-radar link: from the target's reflected intensity to detected return photons.

The rendered radiant intensity ``I(lambda)`` of the target toward the receiver [W sr-1 nm-1],
for the laser's spectral irradiance at the target (after the uplink atmosphere), replaces the
target term of the classical link equation. The receiver then collects

    Phi(lambda) = I(lambda) T_down(lambda) A_rx / R_rx²          [W nm-1]

and detects ``sum_lambda Phi tau_opt eta R_b lambda/(hc) dlambda`` photo-electrons per
second in band b (the pipeline's photon kernel); per pulse, divide by the repetition rate.
For a target of optical cross-section ``sigma = 4 pi I / E`` this is the standard laser-radar
(radar) equation for the number of photo-electrons per pulse

    n = eta_q (E_T lambda / hc) eta_t G_t sigma (1 / (4 pi R²))² A_r eta_r T_a²

with the far-field gain ``G_t = 8/theta_t²`` of a Gaussian beam of 1/e² half-angle
divergence ``theta_t`` (Degnan 1993, "Millimeter accuracy satellite laser ranging: a review",
AGU Geodynamics Series 25, eq. 2.1 and 2.4, doi:10.1029/GD025p0133), written out in
:func:`cross_section_link_photons` for targets given by a cross-section.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from speclight.constants import C_M_S, H_J_S

F64 = NDArray[np.float64]


def photons_from_intensity(
    intensity_W_sr_nm: F64,
    transmission_down: F64,
    aperture_area_m2: float,
    range_rx_m: F64,
    photon_kernel: F64,
) -> F64:
    """Detected photo-electrons per second (N, B) from the intensity toward the receiver.

    Parameters
    ----------
    intensity_W_sr_nm
        (N, L) radiant intensity toward the receiver [W sr-1 nm-1] (mean power).
    transmission_down
        (N, L) atmospheric transmission target -> receiver [1].
    aperture_area_m2
        Receiver collecting area [m²].
    range_rx_m
        (N,) target-to-receiver distance [m].
    photon_kernel
        (B, L) electrons per joule per bin x bin width [nm J-1]
        (:func:`speclight.instrument.photometry.photon_kernel`).

    Returns
    -------
    numpy.ndarray
        (N, B) [s-1]. Divide by the repetition rate for photo-electrons per pulse.
    """
    flux = intensity_W_sr_nm * transmission_down * aperture_area_m2 / range_rx_m[:, None] ** 2
    return np.asarray(flux @ photon_kernel.T)


def band_histograms(histogram: F64, conversion: F64) -> F64:
    """Band-resolved histograms (N, B, nbins) from per-wavelength ones (N, S, nbins).

    ``conversion`` (N, S, B) maps an intensity on the support wavelength s to a detected
    count in band b (transmission x area / range² x photon kernel).
    """
    return np.asarray(np.einsum("nsk,nsb->nbk", histogram, conversion))


def mean_offset_m(moment: F64, total: F64, conversion: F64) -> F64:
    """Return-weighted mean range offset per band (N, B) [m]: sum(I delta c) / sum(I c).

    NaN where a band receives nothing.
    """
    num = np.einsum("ns,nsb->nb", moment, conversion)
    den = np.einsum("ns,nsb->nb", total, conversion)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.asarray(np.where(den > 0, num / den, np.nan))


def cross_section_link_photons(
    pulse_energy_J: float,
    wavelength_nm: float,
    divergence_full_rad: float,
    cross_section_m2: float,
    range_m: float,
    aperture_area_m2: float,
    transmission_one_way: float = 1.0,
    efficiency: float = 1.0,
) -> float:
    """Photo-electrons per pulse from Degnan's link equation for a target cross-section [1].

    ``n = eta (E lambda/hc) G_t sigma / (4 pi R²)² A T²`` with ``G_t = 8 / (theta/2)²``
    (monostatic, target on the beam axis; Degnan 1993, doi:10.1029/GD025p0133, eq. 2.1, 2.4).
    """
    photons = pulse_energy_J * wavelength_nm * 1e-9 / (H_J_S * C_M_S)
    gain = 8.0 / (divergence_full_rad / 2.0) ** 2
    geometric = (1.0 / (4.0 * np.pi * range_m**2)) ** 2
    return float(
        efficiency
        * photons
        * gain
        * cross_section_m2
        * geometric
        * aperture_area_m2
        * transmission_one_way**2
    )
