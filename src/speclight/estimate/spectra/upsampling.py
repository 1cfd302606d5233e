"""Spectral upsampling: a smooth reflectance spectrum from n band albedos.

The reference paper's section 5.1 (Nussbaum et al. 2022, eq. 3 and 4) extends the
sigmoid-polynomial model of Jakob & Hanika (2019, "A Low-Dimensional Function Space for
Efficient Spectral Upsampling", Computer Graphics Forum 38(2), 147-155,
doi:10.1111/cgf.13626) from three tristimulus values to n arbitrary bands:

.. math::

    g(\\lambda) = S(p(\\lambda)), \\qquad S(x) = \\frac{1}{2} + \\frac{x}{2\\sqrt{1 + x^2}},

with p a polynomial of order n - 1, whose n coefficients are fitted so that the
photon-weighted band averages of g equal the band albedos:

.. math::

    \\rho_j = \\frac{\\int g(\\lambda) R_j(\\lambda) \\lambda / (h c) \\, d\\lambda}
                   {\\int R_j(\\lambda) \\lambda / (h c) \\, d\\lambda}.

Here p is written in the Legendre basis of the scaled wavelength
``x = (lambda - centre_nm) / half_span_nm``, which maps the grid onto [-1, 1] (``centre_nm``
and ``half_span_nm`` are the mid-point and half the distance of the first and last grid
wavelengths); the basis only conditions the fit, the family of spectra is the same as with
monomials in nm. Every wavelength integral is a bin sum over
:func:`speclight.wavelength_grid.bin_widths_nm`.

The fit is a square system of n equations in n unknowns. It is solved by
:func:`scipy.optimize.least_squares` on the residuals ``S^-1(model) - S^-1(rho)``, which
vanish at the same point as ``model - rho`` but stay nearly linear in the coefficients where
the sigmoid saturates; the start is the Legendre interpolant of ``S^-1(rho_j)`` at the band
centroids. Albedos of exactly 0 or 1 would need infinite coefficients, so non-grey input is
clipped to ``[clip, 1 - clip]`` first (:data:`ALBEDO_CLIP`); grey input (all albedos
equal, including n = 1) is returned as the constant spectrum without a fit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.polynomial import legendre
from numpy.typing import ArrayLike, NDArray

from speclight.constants import HC_J_M
from speclight.errors import InputError
from speclight.wavelength_grid import bin_widths_nm, check_wavelength_grid

#: Default clipping of non-grey albedos to ``[ALBEDO_CLIP, 1 - ALBEDO_CLIP]`` [1]. It keeps
#: the coefficients finite (``|S^-1| <= 1 / (2 sqrt(ALBEDO_CLIP))``, about 50) and costs at
#: most ``ALBEDO_CLIP`` = 1e-4 in each reproduced band albedo, ten times below the 1e-3 to
#: which upsampling promises to reproduce its input and far below the percent-level
#: uncertainty of albedos fitted to light curves.
ALBEDO_CLIP = 1e-4

#: Default largest band-albedo error [1] for which a fit counts as converged.
BAND_TOLERANCE = 1e-8


@dataclass(frozen=True)
class UpsampledSpectrum:
    """A reflectance spectrum upsampled from band albedos.

    Attributes
    ----------
    wavelength_nm
        The grid [nm] (L,).
    reflectance
        The spectrum g(lambda) on the grid [1] (L,), in [0, 1].
    coefficients
        Legendre coefficients of p in the scaled wavelength (n,), lowest order first;
        ``±inf`` in the first entry for a grey spectrum of 0 or 1.
    centre_nm, half_span_nm
        The scaling ``x = (lambda - centre_nm) / half_span_nm`` of p [nm].
    albedo
        The input band albedos [1] (n,).
    albedo_target
        The albedos that were fitted [1] (n,): the input clipped to ``[clip, 1 - clip]``
        (the input itself for grey input).
    albedo_fit
        The photon-weighted band averages of ``reflectance`` [1] (n,) (eq. 3).
    max_band_error
        ``max |albedo_fit - albedo|`` [1]; it includes the clipping.
    converged
        Whether ``max |albedo_fit - albedo_target| <= tol``.
    """

    wavelength_nm: NDArray[np.float64]
    reflectance: NDArray[np.float64]
    coefficients: NDArray[np.float64]
    centre_nm: float
    half_span_nm: float
    albedo: NDArray[np.float64]
    albedo_target: NDArray[np.float64]
    albedo_fit: NDArray[np.float64]
    max_band_error: float
    converged: bool


def sigmoid(x: ArrayLike) -> NDArray[np.float64]:
    """Jakob & Hanika's sigmoid ``S(x) = 1/2 + x / (2 sqrt(1 + x^2))`` (eq. 4) [1].

    Evaluated without cancellation near 0 and 1 (``S(-|x|) = 1 / (2 t (t + |x|))`` with
    ``t = sqrt(1 + x^2)``); ``S(-inf) = 0``, ``S(inf) = 1``.
    """
    xx = np.asarray(x, dtype=np.float64)
    t = np.hypot(1.0, xx)
    with np.errstate(invalid="ignore"):
        low = 1.0 / (2.0 * t * (t + np.abs(xx)))
    low = np.where(np.isinf(xx), 0.0, low)
    return np.asarray(np.where(xx < 0, low, 1.0 - low), dtype=np.float64)


def inverse_sigmoid(y: ArrayLike) -> NDArray[np.float64]:
    """Inverse of eq. 4, ``S^-1(y) = (2 y - 1) / (2 sqrt(y (1 - y)))`` for y in [0, 1].

    ``S^-1(0) = -inf`` and ``S^-1(1) = inf``.
    """
    yy = np.asarray(y, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = (2.0 * yy - 1.0) / (2.0 * np.sqrt(yy * (1.0 - yy)))
    return np.asarray(out, dtype=np.float64)


def _sigmoid_slope(x: NDArray[np.float64]) -> NDArray[np.float64]:
    """``S'(x) = 1 / (2 (1 + x^2)^(3/2))``."""
    return np.asarray(0.5 / np.hypot(1.0, x) ** 3, dtype=np.float64)


def scaled_wavelength(
    wavelength_nm: ArrayLike, centre_nm: float, half_span_nm: float
) -> NDArray[np.float64]:
    """``x = (lambda - centre_nm) / half_span_nm`` [1], the argument of p."""
    return (np.asarray(wavelength_nm, dtype=np.float64) - centre_nm) / half_span_nm


def sigmoid_polynomial(
    coefficients: ArrayLike, wavelength_nm: ArrayLike, centre_nm: float, half_span_nm: float
) -> NDArray[np.float64]:
    """Evaluate ``S(p(x))`` [1] for Legendre coefficients of p in the scaled wavelength.

    Parameters
    ----------
    coefficients
        Legendre coefficients (n,), lowest order first (as :attr:`UpsampledSpectrum.coefficients`).
    wavelength_nm
        Wavelengths [nm] (L,).
    centre_nm, half_span_nm
        The scaling of :func:`scaled_wavelength` [nm].

    Returns
    -------
    numpy.ndarray
        The reflectance [1] (L,).
    """
    c = np.asarray(coefficients, dtype=np.float64)
    if c.size and np.isinf(c[0]) and not np.any(c[1:]):
        return np.full(np.shape(wavelength_nm), sigmoid(c[0]), dtype=np.float64)
    x = scaled_wavelength(wavelength_nm, centre_nm, half_span_nm)
    return sigmoid(legendre.legval(x, c))


def photon_weights(band_response: ArrayLike, wavelength_nm: ArrayLike) -> NDArray[np.float64]:
    """Normalised photon weights of eq. 3 [1] (n, L): ``R_j lambda / (h c) dl`` over its sum.

    Parameters
    ----------
    band_response
        Band responses on the grid (n, L) (band response x optics x QE) [1].
    wavelength_nm
        The grid [nm] (L,).

    Returns
    -------
    numpy.ndarray
        Weights whose rows sum to 1; ``weights @ g`` are the band albedos of ``g``.
    """
    wl = np.asarray(wavelength_nm, dtype=np.float64)
    photons = np.asarray(band_response, dtype=np.float64) * (wl * 1e-9 / HC_J_M)
    w = photons * bin_widths_nm(wl)
    return np.asarray(w / w.sum(axis=-1, keepdims=True), dtype=np.float64)


def band_albedo(
    reflectance: ArrayLike, band_response: ArrayLike, wavelength_nm: ArrayLike
) -> NDArray[np.float64]:
    """Photon-weighted band averages of a reflectance spectrum (eq. 3) [1] (n,).

    Parameters
    ----------
    reflectance
        The spectrum on the grid [1] (L,).
    band_response
        Band responses on the grid (n, L) [1].
    wavelength_nm
        The grid [nm] (L,).
    """
    wl, response = _check_grid_and_response(band_response, wavelength_nm)
    g = np.asarray(reflectance, dtype=np.float64)
    if g.shape != wl.shape:
        raise InputError(
            f"reflectance has shape {g.shape}, expected {wl.shape} (one value per wavelength)",
            field="reflectance",
        )
    return np.asarray(photon_weights(response, wl) @ g, dtype=np.float64)


def _check_grid_and_response(
    band_response: ArrayLike, wavelength_nm: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    try:
        wl = check_wavelength_grid(wavelength_nm)
    except InputError as err:
        raise InputError(err.message, field="wavelength_nm") from None
    response = np.asarray(band_response, dtype=np.float64)
    if response.ndim != 2 or response.shape[1] != wl.size:
        raise InputError(
            f"band_response has shape {response.shape}, expected (n_bands, {wl.size}) "
            f"(one row per band on the {wl.size}-point wavelength grid)",
            field="band_response",
        )
    if not np.all(np.isfinite(response)) or np.any(response < 0):
        raise InputError("band_response must be finite and >= 0", field="band_response")
    empty = np.flatnonzero(~(response.sum(axis=1) > 0))
    if empty.size:
        raise InputError(
            f"band_response rows {empty.tolist()} are zero on the whole wavelength grid "
            "(each band needs some response inside the grid)",
            field="band_response",
        )
    return wl, response


def upsample(
    albedo: ArrayLike,
    band_response: ArrayLike,
    wavelength_nm: ArrayLike,
    *,
    clip: float = ALBEDO_CLIP,
    tol: float = BAND_TOLERANCE,
    max_iterations: int = 200,
) -> UpsampledSpectrum:
    """Reflectance spectrum from n band albedos (reference paper eq. 3-4).

    Parameters
    ----------
    albedo
        Band albedos rho_j [1] (n,), each in [0, 1].
    band_response
        Band responses R_j on the grid (n, L) [1]: the scenario's band response x optics
        transmission x detector QE; bands may overlap.
    wavelength_nm
        The grid [nm] (L,), strictly increasing, L >= 2 and L >= n.
    clip
        Non-grey albedos are clipped to ``[clip, 1 - clip]`` before the fit [1]; this
        costs at most ``clip`` in each band (see :data:`ALBEDO_CLIP`).
    tol
        Largest band error ``|albedo_fit - albedo_target|`` [1] for ``converged``.
    max_iterations
        Cap on the solver's function evaluations, in units of n + 1.

    Returns
    -------
    UpsampledSpectrum
        The spectrum, its coefficients, the band albedos it reproduces and whether the fit
        converged. A fit that does not converge (e.g. albedos that no polynomial of order
        n - 1 can produce through strongly overlapping bands) is returned with
        ``converged = False``, not raised.

    Raises
    ------
    InputError
        For an albedo that is not a finite 1-D array in [0, 1], a band response that is not
        (n, L), negative, non-finite or zero on the grid, a bad grid, or more bands than
        wavelengths.

    References
    ----------
    Jakob, W. & Hanika, J. (2019). A Low-Dimensional Function Space for Efficient Spectral
    Upsampling. Computer Graphics Forum 38(2), 147-155. doi:10.1111/cgf.13626
    """
    wl, response = _check_grid_and_response(band_response, wavelength_nm)
    rho = np.asarray(albedo, dtype=np.float64)
    n = response.shape[0]
    if rho.ndim != 1 or rho.size < 1:
        raise InputError(
            f"albedo must be a 1-D array of band albedos, got shape {rho.shape}", field="albedo"
        )
    if rho.size != n:
        raise InputError(
            f"albedo has {rho.size} values but band_response has {n} bands", field="albedo"
        )
    bad = np.flatnonzero(~((rho >= 0) & (rho <= 1)))
    if bad.size:
        raise InputError(
            f"albedo = {rho[bad].tolist()} (bands {bad.tolist()}) must be in [0, 1]",
            field="albedo",
        )
    if n > wl.size:
        raise InputError(
            f"{n} bands need at least {n} wavelengths, the grid has {wl.size}",
            field="band_response",
        )
    if not 0 < clip < 0.5:
        raise InputError(f"clip = {clip!r} must be in (0, 0.5)", field="clip")
    if not tol > 0:
        raise InputError(f"tol = {tol!r} must be > 0", field="tol")

    centre = 0.5 * (wl[0] + wl[-1])
    half_span = 0.5 * (wl[-1] - wl[0])
    weights = photon_weights(response, wl)

    if np.all(rho == rho[0]):
        coefficients = np.zeros(n)
        coefficients[0] = inverse_sigmoid(rho[0])
        reflectance = np.full(wl.size, rho[0])
        fit = weights @ reflectance
        return _result(wl, reflectance, coefficients, centre, half_span, rho, rho.copy(), fit, tol)

    from scipy.optimize import least_squares  # here: importing scipy.optimize costs ~0.3 s

    target = np.clip(rho, clip, 1.0 - clip)
    vander = legendre.legvander(scaled_wavelength(wl, centre, half_span), n - 1)
    target_inv = inverse_sigmoid(target)

    def model(c: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        p = vander @ c
        return weights @ sigmoid(p), p

    def residual(c: NDArray[np.float64]) -> NDArray[np.float64]:
        a, _ = model(c)
        return inverse_sigmoid(np.clip(a, 1e-300, 1.0 - 1e-16)) - target_inv

    def jacobian(c: NDArray[np.float64]) -> NDArray[np.float64]:
        a, p = model(c)
        da = weights @ (_sigmoid_slope(p)[:, None] * vander)
        inv = inverse_sigmoid(np.clip(a, 1e-300, 1.0 - 1e-16))
        return np.asarray(2.0 * np.hypot(1.0, inv)[:, None] ** 3 * da, dtype=np.float64)

    # Start: the Legendre polynomial through S^-1(rho_j) at the photon-weighted band centroids.
    centroid_x = scaled_wavelength(weights @ wl, centre, half_span)
    start = np.linalg.lstsq(legendre.legvander(centroid_x, n - 1), target_inv, rcond=None)[0]
    solution = least_squares(
        residual,
        start,
        jac=jacobian,
        method="lm",
        x_scale="jac",
        xtol=1e-15,
        ftol=1e-15,
        gtol=1e-15,
        max_nfev=max_iterations * (n + 1),
    )
    coefficients = np.asarray(solution.x, dtype=np.float64)
    reflectance = sigmoid(vander @ coefficients)
    fit = weights @ reflectance
    return _result(wl, reflectance, coefficients, centre, half_span, rho, target, fit, tol)


def _result(
    wl: NDArray[np.float64],
    reflectance: NDArray[np.float64],
    coefficients: NDArray[np.float64],
    centre: float,
    half_span: float,
    rho: NDArray[np.float64],
    target: NDArray[np.float64],
    fit: NDArray[np.float64],
    tol: float,
) -> UpsampledSpectrum:
    fit_error = float(np.max(np.abs(fit - target)))
    return UpsampledSpectrum(
        wavelength_nm=wl,
        reflectance=reflectance,
        coefficients=coefficients,
        centre_nm=float(centre),
        half_span_nm=float(half_span),
        albedo=rho,
        albedo_target=target,
        albedo_fit=np.asarray(fit, dtype=np.float64),
        max_band_error=float(np.max(np.abs(fit - rho))),
        converged=bool(np.isfinite(fit_error) and fit_error <= tol),
    )


__all__ = [
    "ALBEDO_CLIP",
    "BAND_TOLERANCE",
    "UpsampledSpectrum",
    "band_albedo",
    "inverse_sigmoid",
    "photon_weights",
    "sigmoid",
    "sigmoid_polynomial",
    "upsample",
]
