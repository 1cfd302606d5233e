"""Unmixing against a known truth: material signatures, true contributions, accuracy.

For simulated light curves with ``render: {per_material: true}`` the output carries each
material's share of the band reflectance factors (``reflectance_factor_material``, or
``laser_reflectance_factor_material`` under lasers; :mod:`speclight.simulation.per_material`).
Where a material's BRDF is its reflectance spectrum times a geometric factor (Lambertian, and
microfacet models with the reflectance given as numbers), its share is
``F_k(t, j) = g_k(t) s_kj``: a contribution ``g_k(t)`` [m2 sr-1] times the band signature
``s_kj``, the band average of the reflectance weighted by the detected photons,

    s_kj = sum_l rho_k(l) E(l) R_j(l) l dl / sum_l E(l) R_j(l) l dl,

with ``E`` the source spectrum at the aperture (the Sun or the lasers' lines, times the
atmosphere's transmission: :mod:`speclight.estimate.inputs.source_spectrum`; per epoch, since the
transmission changes along a pass) and ``R_j`` the band response x optics x QE (the weights
of eq. 5, Nussbaum et al. 2022, doi:10.3390/aerospace9040214; :func:`band_albedo` with
``E R_j`` as the response). The true contribution is then the projection
``g_k = F_k . s_k / |s_k|^2`` (exact for such materials), and the true fractions
``g_k / sum g`` are what ``nnls-norm`` estimates (:func:`speclight.estimate.unmix`,
:func:`.unmix_per_epoch`); the comparison of ``speclight unmix`` is
:mod:`speclight.estimate.spectra.unmix_truth`, with the confusion matrix and spectral angle of
:mod:`speclight.estimate.spectra.accuracy`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError
from speclight.estimate.spectra.accuracy import (
    confusion_matrix,
    mean_absolute_share_error,
    spectral_angle_rad,
)
from speclight.estimate.spectra.unmixing import UnmixMethod
from speclight.estimate.spectra.unmixing_epochs import unmix_per_epoch
from speclight.estimate.spectra.upsampling import band_albedo, photon_weights

F64 = NDArray[np.float64]


def material_signatures(
    reflectance: ArrayLike,
    band_response: ArrayLike,
    wavelength_nm: ArrayLike,
    source_W_m2_nm: ArrayLike | None = None,
) -> F64:
    """Band signatures (K, B) [1] of K reflectance spectra (K, L) (module docstring).

    ``band_response`` (B, L) is band response x optics x QE; ``source_W_m2_nm`` the source
    spectrum at the aperture (:mod:`speclight.estimate.inputs.source_spectrum`): (L,) for one
    signature matrix, (N, L) for one per epoch, then the result is (N, K, B) (NaN for an
    epoch without light); None: a flat source, the plain photon-weighted band averages of
    :func:`speclight.estimate.spectra.upsampling.band_albedo`.
    """
    rho = np.atleast_2d(np.asarray(reflectance, dtype=np.float64))
    response = np.asarray(band_response, dtype=np.float64)
    if source_W_m2_nm is None:
        return np.stack([band_albedo(r, response, wavelength_nm) for r in rho])
    source = np.asarray(source_W_m2_nm, dtype=np.float64)
    if source.ndim == 1:
        return np.stack([band_albedo(r, response * source, wavelength_nm) for r in rho])
    # sum_l rho E P / sum_l E P with P the photon weights of the bands (their normalisation
    # cancels): two matrix products over the grid, no (N, B, L) array
    p = photon_weights(response, wavelength_nm)
    k, b = rho.shape[0], p.shape[0]
    num = source @ (rho[:, None, :] * p[None, :, :]).reshape(k * b, -1).T
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.asarray(num.reshape(-1, k, b) / (source @ p.T)[:, None, :])


def true_contributions(
    factor_material: ArrayLike,
    material_labels: list[str],
    endmember_labels: list[str],
    signatures: ArrayLike,
) -> F64:
    """True contributions (N, K) [m2 sr-1] of K endmembers from per-material factors.

    ``factor_material`` (N, M, B) are the materials' shares of the band reflectance factors;
    the materials whose label is ``endmember_labels[k]`` are summed, and projected on the
    signature ``signatures[k]`` (B,) (or ``signatures[n, k]`` for per-epoch signatures
    (N, K, B)): ``g_k = F_k . s_k / |s_k|^2``.
    """
    f = np.asarray(factor_material, dtype=np.float64)
    s = np.asarray(signatures, dtype=np.float64)
    if s.ndim == 2:
        s = np.broadcast_to(s, (f.shape[0], *s.shape))
    labels = np.asarray(material_labels)
    unknown = sorted(set(material_labels) - set(endmember_labels))
    if unknown:
        raise InputError(
            f"materials {unknown} have no endmember (endmembers: {', '.join(endmember_labels)})",
            field="endmember_labels",
        )
    out = np.empty((f.shape[0], len(endmember_labels)))
    for k, name in enumerate(endmember_labels):
        share = f[:, labels == name, :].sum(axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            out[:, k] = np.einsum("nb,nb->n", share, s[:, k]) / np.einsum(
                "nb,nb->n", s[:, k], s[:, k]
            )
    return out


def fractions(contributions: ArrayLike) -> F64:
    """Contributions (N, K) divided by their sum over K (NaN where the sum is not > 0)."""
    a = np.asarray(contributions, dtype=np.float64)
    total = a.sum(axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.asarray(np.where(total > 0, a / total, np.nan))


@dataclass(frozen=True)
class UnmixAccuracy:
    """How well an unmixing recovered the true fractions.

    Attributes
    ----------
    estimated
        (N, K) estimated fractions (NaN rows where ``x`` or the truth is not finite).
    confusion
        (K, K) dominant-endmember confusion matrix, rows true, columns estimated.
    mean_abs_error
        Mean over epochs and endmembers of ``|estimated - true|`` fraction [1].
    max_abs_error
        Largest ``|estimated - true|`` fraction [1].
    n_epochs
        Epochs compared.
    """

    estimated: F64
    confusion: NDArray[np.int64]
    mean_abs_error: float
    max_abs_error: float
    n_epochs: int

    @property
    def dominant_accuracy(self) -> float:
        """Fraction of the epochs whose dominant endmember is found."""
        return float(np.trace(self.confusion) / max(self.confusion.sum(), 1))


def unmix_accuracy(
    x: ArrayLike,
    true_fraction: ArrayLike,
    signatures: ArrayLike,
    method: UnmixMethod = "nnls-norm",
) -> UnmixAccuracy:
    """Unmix ``x`` (N, B) with ``signatures`` (K, B), or per epoch (N, K, B)
    (:func:`speclight.estimate.spectra.unmixing.unmix_per_epoch`), and compare with
    ``true_fraction`` (N, K)."""
    t = np.asarray(true_fraction, dtype=np.float64)
    est = unmix_per_epoch(x, signatures, method=method).abundance
    ok = np.all(np.isfinite(t), axis=1) & np.all(np.isfinite(est), axis=1)
    est = np.where(ok[:, None], est, np.nan)
    err = np.abs(est[ok] - t[ok])
    return UnmixAccuracy(
        estimated=est,
        confusion=confusion_matrix(t, est, normalise=False).astype(np.int64),
        mean_abs_error=mean_absolute_share_error(t, est),
        max_abs_error=float(err.max()) if err.size else float("nan"),
        n_epochs=int(ok.sum()),
    )


def matched_angles_deg(true_signatures: ArrayLike, extracted: ArrayLike) -> tuple[F64, F64]:
    """Pair extracted signatures with true ones by smallest total spectral angle.

    Returns the angle [deg] of each true signature to its partner (K,) and the index of the
    partner in ``extracted`` (K,) (Hungarian assignment, scipy ``linear_sum_assignment``).
    An extracted signature of zeros (a dark epoch) pairs at NaN, as if at 180 deg.
    """
    from scipy.optimize import linear_sum_assignment  # here: scipy.optimize costs ~0.3 s

    s = np.atleast_2d(np.asarray(true_signatures, dtype=np.float64))
    e = np.atleast_2d(np.asarray(extracted, dtype=np.float64))
    cost = np.degrees(spectral_angle_rad(s, e))
    rows, cols = linear_sum_assignment(np.nan_to_num(cost, nan=180.0))
    angle = np.full(len(s), np.nan)
    partner = np.full(len(s), -1.0)
    angle[rows] = cost[rows, cols]
    partner[rows] = cols
    return angle, partner
