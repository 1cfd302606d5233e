"""Photo-electron rates of stars in the scenario's bands.

A star's spectrum is taken as a black body at the temperature its B-V gives (Ballesteros
2012, EPL 97, 34008, eq. 14, doi:10.1209/0295-5075/97/34008)

.. math:: T = 4600\\,\\mathrm{K}\\left(\\frac{1}{0.92 (B-V) + 1.7}
          + \\frac{1}{0.92 (B-V) + 0.62}\\right)

scaled so that its Vega V magnitude (speclite's ``bessell-V``,
:func:`~speclight.instrument.vega_v_magnitude`) is the catalogue's V, and sent through the
same chain as the target: the atmosphere's transmission of the target's line of sight (the
field is small), the aperture, optics, detector and band
(:func:`~speclight.instrument.photometry.photon_kernel`). A black body matches real stellar
spectra to ~0.1 mag in broad optical bands; absorption lines and the Balmer jump are not in it.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.constants import C_M_S, H_J_S, K_B_J_K
from speclight.errors import InputError
from speclight.instrument.magnitudes import vega_v_magnitude
from speclight.instrument.photometry import photon_kernel

F64 = NDArray[np.float64]


def temperature_from_b_v(b_v: ArrayLike) -> F64:
    """Black-body temperature [K] of a star of colour B-V [mag] (Ballesteros 2012)."""
    x = 0.92 * np.clip(np.asarray(b_v, dtype=np.float64), -0.4, 2.5)
    return np.asarray(4600.0 * (1.0 / (x + 1.7) + 1.0 / (x + 0.62)))


def planck_W_m2_nm_sr(wavelength_nm: ArrayLike, temperature_K: ArrayLike) -> F64:
    """Black-body spectral radiance B_lambda [W m-2 sr-1 nm-1], shape (S, L)."""
    wl = np.asarray(wavelength_nm, dtype=np.float64)[None, :] * 1e-9
    t = np.asarray(temperature_K, dtype=np.float64)[:, None]
    with np.errstate(over="ignore"):
        b = 2.0 * H_J_S * C_M_S**2 / wl**5 / np.expm1(H_J_S * C_M_S / (wl * K_B_J_K * t))
    return np.asarray(b * 1e-9)


def star_count_rates(
    v_mag: ArrayLike,
    b_v: ArrayLike,
    wavelength_nm: ArrayLike,
    transmission: ArrayLike,
    aperture_area_m2: float,
    optics: ArrayLike,
    qe: ArrayLike,
    band_response: ArrayLike,
) -> F64:
    """Detected photo-electron rate of each star in each band.

    Parameters
    ----------
    v_mag, b_v
        (S,) Johnson V and B-V [mag].
    wavelength_nm
        (L,) grid [nm]; it must cover the V band (480-700 nm).
    transmission
        (L,) atmospheric transmission toward the field [1].
    aperture_area_m2
        Collecting area [m2].
    optics
        (L,) optics transmission [1].
    qe
        (B, L) detector quantum efficiency per band [1].
    band_response
        (B, L) band responses [1].

    Returns
    -------
    numpy.ndarray
        (S, B) [s-1].
    """
    v = np.asarray(v_mag, dtype=np.float64)
    wl = np.asarray(wavelength_nm, dtype=np.float64)
    shape = planck_W_m2_nm_sr(wl, temperature_from_b_v(b_v))  # (S, L), any scale
    v_of_shape = vega_v_magnitude(shape * aperture_area_m2, aperture_area_m2, wl)
    if v_of_shape is None:
        raise InputError(
            f"the wavelength grid {wl[0]:g}..{wl[-1]:g} nm does not cover the V band, which "
            "sets the stars' brightness: widen spectrum.min_nm / max_nm (480-700 nm) or give "
            "stars: {catalogue: none}",
            field="instrument.imaging.stars",
        )
    irradiance = shape * 10.0 ** (-0.4 * (v - v_of_shape))[:, None]  # W m-2 nm-1
    qe2 = np.atleast_2d(np.asarray(qe, dtype=np.float64))
    bands = np.atleast_2d(np.asarray(band_response, dtype=np.float64))
    rates = np.empty((v.size, bands.shape[0]))
    t = np.asarray(transmission, dtype=np.float64)
    for b in range(bands.shape[0]):
        kernel = photon_kernel(wl, optics, qe2[b], bands[b])[0]  # e- per J per bin
        rates[:, b] = aperture_area_m2 * (irradiance * t[None, :]) @ kernel
    return rates
