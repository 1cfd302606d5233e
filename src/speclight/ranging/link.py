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
AGU Geodynamics Series 25, eq. 2.1 and 2.4, doi:10.1029/GD025p0133); the test suite checks
the two against each other for a sphere.

The uplink (:func:`uplink_spectral_irradiance`) and the downlink (:func:`receiver_returns`)
are both here: the pipeline calls these functions and does no link arithmetic of its own.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]


def uplink_spectral_irradiance(
    beam_W_m2: F64, line_per_nm: F64, transmission_up: F64, lit: NDArray[np.bool_]
) -> F64:
    """Spectral irradiance of a laser at the target on its support (N, S) [W m-2 nm-1].

    ``beam_W_m2`` (N,) is the beam irradiance above the atmosphere, ``line_per_nm`` (S,) the
    line shape on the support bins, ``transmission_up`` (N, S) the uplink transmission and
    ``lit`` (N,) where the laser reaches the target (0 elsewhere).
    """
    spectral = beam_W_m2[:, None] * line_per_nm[None, :] * transmission_up
    return np.asarray(np.where(lit[:, None], spectral, 0.0))


def uplink_irradiance_W_m2(spectral_W_m2_nm: F64, bin_width_nm: F64, ok: NDArray[np.bool_]) -> F64:
    """Laser irradiance at the target (N,) [W m-2]: the bin sum of the spectral irradiance
    (N, S) with the support's bin widths (S,) [nm]; NaN where ``ok`` is false."""
    return np.asarray(np.where(ok, spectral_W_m2_nm @ bin_width_nm, np.nan))


def downlink_conversion(
    transmission_down: F64,
    observable: NDArray[np.bool_],
    range_rx_m: F64,
    aperture_area_m2: float,
    photon_kernel: F64,
) -> F64:
    """Detected counts per second per unit intensity (N, S, B) [s-1 per W sr-1 nm-1].

    Parameters
    ----------
    transmission_down
        (N, S) atmospheric transmission target -> receiver on a laser's support [1].
    observable
        (N,) epochs whose returns reach the receiver (0 elsewhere).
    range_rx_m
        (N,) target-to-receiver distance [m].
    aperture_area_m2
        Receiver collecting area [m²].
    photon_kernel
        (B, S) electrons per joule per bin x bin width [nm J-1] on the support
        (:func:`speclight.instrument.photometry.photon_kernel`).
    """
    with np.errstate(invalid="ignore"):
        down = np.where(observable[:, None], transmission_down, 0.0)
        down = (
            np.nan_to_num(down)
            * aperture_area_m2
            / np.where(observable, range_rx_m, 1.0)[:, None] ** 2
        )
    return np.asarray(down[:, :, None] * photon_kernel.T[None, :, :])


def band_rates(values: F64, conversion: F64) -> F64:
    """Band values (N, B) from values on a laser's support (N, S): ``sum_s x c``.

    With intensities [W sr-1 nm-1] this gives count rates [s-1]; with first moments
    (intensity x offset) the count-weighted offsets [s-1 m].
    """
    return np.asarray(np.einsum("ns,nsb->nb", values, conversion))


def band_histograms(histogram: F64, conversion: F64) -> F64:
    """Band-resolved histograms (N, B, nbins) from per-wavelength ones (N, S, nbins).

    ``conversion`` (N, S, B) maps an intensity on the support wavelength s to a detected
    count in band b (:func:`downlink_conversion`).
    """
    return np.asarray(np.einsum("nsk,nsb->nbk", histogram, conversion))


@dataclass
class ReceiverReturns:
    """What the receiver detects from all lasers, per band.

    Attributes
    ----------
    per_pulse
        (N, K, B) return photo-electrons per pulse of each laser [1].
    rate_per_s
        (N, B) return photo-electrons per second, all lasers [s-1].
    histogram_per_s
        (N, B, nbins) the same per range-offset bin [s-1].
    offset_m
        (N, B) count-weighted mean range offset [m] (NaN where a band receives nothing).
    """

    per_pulse: F64
    rate_per_s: F64
    histogram_per_s: F64
    offset_m: F64


def receiver_returns(
    histograms: list[F64],
    moments_m: list[F64],
    conversions: list[F64],
    repetition_rate_hz: list[float],
) -> ReceiverReturns:
    """Carry each laser's rendered returns to the receiver's bands and sum the lasers.

    Parameters
    ----------
    histograms, moments_m
        Per laser k: intensity histograms (N, S_k, nbins) [W sr-1 nm-1 per bin] and first
        moments (N, S_k) [W sr-1 nm-1 m] on its support (the render's output).
    conversions
        Per laser: :func:`downlink_conversion` (N, S_k, B).
    repetition_rate_hz
        Per laser: pulses per second.
    """
    n, n_bins = histograms[0].shape[0], histograms[0].shape[2]
    n_b = conversions[0].shape[2]
    per_pulse = np.zeros((n, len(histograms), n_b))
    hist = np.zeros((n, n_b, n_bins))
    moment = np.zeros((n, n_b))
    total = np.zeros((n, n_b))
    for k, (h_k, m_k, conv, rate_hz) in enumerate(
        zip(histograms, moments_m, conversions, repetition_rate_hz, strict=True)
    ):
        rate = band_rates(h_k.sum(axis=2), conv)
        per_pulse[:, k] = rate / rate_hz
        hist += band_histograms(h_k, conv)
        moment += band_rates(m_k, conv)
        total += rate
    with np.errstate(invalid="ignore", divide="ignore"):
        offset = np.where(total > 0, moment / total, np.nan)
    return ReceiverReturns(per_pulse, total, hist, offset)
