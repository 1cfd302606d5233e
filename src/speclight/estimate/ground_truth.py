"""Unmixing against a known truth: material signatures, true contributions, accuracy.

For simulated light curves with ``render: {per_material: true}`` the output carries each
material's share of the band reflectance factors (``reflectance_factor_material``, or
``laser_reflectance_factor_material`` under lasers; :mod:`speclight.simulate.per_material`).
Where a material's BRDF is its reflectance spectrum times a geometric factor (Lambertian, and
microfacet models with the reflectance given as numbers), its share is
``F_k(t, j) = g_k(t) s_kj``: a contribution ``g_k(t)`` [m2 sr-1] times the band signature
``s_kj``, the band average of the reflectance weighted by the detected photons,

    s_kj = sum_l rho_k(l) E(l) R_j(l) l dl / sum_l E(l) R_j(l) l dl,

with ``E`` the source spectrum at the aperture (the Sun or the lasers' lines, times the
atmosphere's transmission) and ``R_j`` the band response x optics x QE (the weights of eq. 5,
Nussbaum et al. 2022, doi:10.3390/aerospace9040214; :func:`band_albedo` with ``E R_j`` as
the response). The true contribution is then the projection ``g_k = F_k . s_k / |s_k|^2``
(exact for such materials), and the true fractions ``g_k / sum g`` are what ``nnls-norm``
and ``fcls`` estimate (:func:`speclight.estimate.unmix`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import linear_sum_assignment

from speclight.errors import InputError
from speclight.estimate.unmixing import UnmixMethod, unmix
from speclight.estimate.upsampling import band_albedo

F64 = NDArray[np.float64]


def material_signatures(
    reflectance: ArrayLike,
    band_response: ArrayLike,
    wavelength_nm: ArrayLike,
    source_W_m2_nm: ArrayLike | None = None,
) -> F64:
    """Band signatures (K, B) [1] of K reflectance spectra (K, L) (module docstring).

    ``band_response`` (B, L) is band response x optics x QE; ``source_W_m2_nm`` (L,) the
    source spectrum at the aperture (None: a flat source, the plain photon-weighted band
    averages of :func:`speclight.estimate.upsampling.band_albedo`).
    """
    rho = np.atleast_2d(np.asarray(reflectance, dtype=np.float64))
    response = np.asarray(band_response, dtype=np.float64)
    if source_W_m2_nm is not None:
        response = response * np.asarray(source_W_m2_nm, dtype=np.float64)[None, :]
    return np.stack([band_albedo(r, response, wavelength_nm) for r in rho])


def true_contributions(
    factor_material: ArrayLike,
    material_labels: list[str],
    endmember_labels: list[str],
    signatures: ArrayLike,
) -> F64:
    """True contributions (N, K) [m2 sr-1] of K endmembers from per-material factors.

    ``factor_material`` (N, M, B) are the materials' shares of the band reflectance factors;
    the materials whose label is ``endmember_labels[k]`` are summed, and projected on the
    signature ``signatures[k]`` (B,): ``g_k = F_k . s_k / |s_k|^2``.
    """
    f = np.asarray(factor_material, dtype=np.float64)
    s = np.asarray(signatures, dtype=np.float64)
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
        out[:, k] = share @ s[k] / (s[k] @ s[k])
    return out


def fractions(contributions: ArrayLike) -> F64:
    """Contributions (N, K) divided by their sum over K (NaN where the sum is not > 0)."""
    a = np.asarray(contributions, dtype=np.float64)
    total = a.sum(axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.asarray(np.where(total > 0, a / total, np.nan))


def dominant_confusion(
    true_fraction: ArrayLike, estimated_fraction: ArrayLike
) -> NDArray[np.int64]:
    """Confusion matrix (K, K) of the dominant endmember per epoch: rows true, columns
    estimated; epochs with a NaN in either are left out."""
    t = np.asarray(true_fraction, dtype=np.float64)
    e = np.asarray(estimated_fraction, dtype=np.float64)
    ok = np.all(np.isfinite(t), axis=1) & np.all(np.isfinite(e), axis=1)
    k = t.shape[1]
    out = np.zeros((k, k), dtype=np.int64)
    np.add.at(out, (np.argmax(t[ok], axis=1), np.argmax(e[ok], axis=1)), 1)
    return out


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
    """Unmix ``x`` (N, B) with ``signatures`` (K, B) and compare with ``true_fraction`` (N, K)."""
    t = np.asarray(true_fraction, dtype=np.float64)
    est = unmix(x, signatures, method=method).abundance
    ok = np.all(np.isfinite(t), axis=1) & np.all(np.isfinite(est), axis=1)
    est = np.where(ok[:, None], est, np.nan)
    err = np.abs(est[ok] - t[ok])
    return UnmixAccuracy(
        estimated=est,
        confusion=dominant_confusion(t, est),
        mean_abs_error=float(err.mean()) if err.size else float("nan"),
        max_abs_error=float(err.max()) if err.size else float("nan"),
        n_epochs=int(ok.sum()),
    )


def spectral_angle_deg(a: ArrayLike, b: ArrayLike) -> F64:
    """Spectral angle [deg] between the rows of ``a`` (K, B) and ``b`` (K, B) (or (B,));
    NaN where a row is zero (no direction)."""
    u = np.atleast_2d(np.asarray(a, dtype=np.float64))
    v = np.atleast_2d(np.asarray(b, dtype=np.float64))
    with np.errstate(invalid="ignore", divide="ignore"):
        cos = np.sum(u * v, axis=1) / (np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1))
    return np.asarray(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))


def matched_angles_deg(true_signatures: ArrayLike, extracted: ArrayLike) -> tuple[F64, F64]:
    """Pair extracted signatures with true ones by smallest total spectral angle.

    Returns the angle [deg] of each true signature to its partner (K,) and the index of the
    partner in ``extracted`` (K,) (Hungarian assignment, scipy ``linear_sum_assignment``).
    An extracted signature of zeros (a dark epoch) pairs at NaN, as if at 180 deg.
    """
    s = np.atleast_2d(np.asarray(true_signatures, dtype=np.float64))
    e = np.atleast_2d(np.asarray(extracted, dtype=np.float64))
    cost = np.array([[spectral_angle_deg(si, ej)[0] for ej in e] for si in s])
    rows, cols = linear_sum_assignment(np.nan_to_num(cost, nan=180.0))
    angle = np.full(len(s), np.nan)
    partner = np.full(len(s), -1.0)
    angle[rows] = cost[rows, cols]
    partner[rows] = cols
    return angle, partner


def mean_source_W_m2_nm(
    irradiance_W_m2_nm: ArrayLike, transmission: ArrayLike, weight: ArrayLike | None = None
) -> F64:
    """Source spectrum at the aperture (L,): the mean over epochs of irradiance x transmission.

    ``irradiance_W_m2_nm`` (N, L) at the target (a simulate output's ``solar_irradiance``,
    or the lasers' lines), ``transmission`` (N, L); epochs with a non-finite value, or with a
    zero ``weight`` (N,) (e.g. ``sunlit``), are left out. The signatures weighted with it
    differ from each epoch's exact weights only by the change of the atmosphere's spectral
    shape over the pass.
    """
    e = np.asarray(irradiance_W_m2_nm, dtype=np.float64) * np.asarray(transmission, dtype=float)
    ok = np.all(np.isfinite(e), axis=1)
    if weight is not None:
        ok &= np.asarray(weight, dtype=np.float64) > 0
    if not np.any(ok):
        raise InputError("no epoch with a finite, lit source spectrum", field="irradiance")
    return np.asarray(e[ok].mean(axis=0))


def coaxial_laser_source_W_m2_nm(
    laser_irradiance_W_m2: ArrayLike, line_per_nm: ArrayLike, transmission: ArrayLike
) -> F64:
    """Lasers' spectrum at the aperture (N, L) for transmitters at the observer's site.

    ``laser_irradiance_W_m2`` (N, K) is the simulate output's ``laser_irradiance`` (each
    line's irradiance at the target, after the uplink), ``line_per_nm`` (K, L) the line
    shapes on the grid (on their support, as the pipeline keeps them) and ``transmission``
    (N, L) the observer's. From the observer's own site the uplink has the downlink's
    transmission T, so a line at the target is ``beam x shape x T`` (``laser_irradiance`` its
    bin sum on a uniform grid) and at the aperture ``beam x shape x T^2``.
    """
    irr = np.asarray(laser_irradiance_W_m2, dtype=np.float64)
    lines = np.atleast_2d(np.asarray(line_per_nm, dtype=np.float64))
    t = np.asarray(transmission, dtype=np.float64)
    out = np.zeros_like(t)
    for k in range(len(lines)):
        shaped = lines[k] * t
        with np.errstate(invalid="ignore", divide="ignore"):
            beam = np.where(irr[:, k] > 0, irr[:, k] / shaped.sum(axis=1), 0.0)
        out += beam[:, None] * shaped
    return np.asarray(out * t)
