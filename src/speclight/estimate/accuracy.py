"""How well unmixing recovered the materials: shares, confusion matrix, spectral angle.

Plain arrays in, plain arrays out. The comparison is made on **signal shares**: the fraction
of an epoch's band-summed reflectance factor that each material (or endmember) contributes.

* True shares from ground truth ``contribution[n, m, b]``, each material's part of the band
  reflectance factor (``reflectance_factor_material`` of a simulation): ``sum_b c[n, m, b]``
  over ``sum_{m, b} c[n, m, b]``.
* Estimated shares from the contributions ``a`` and signatures ``S`` of eq. 6: endmember k
  contributes ``a[n, k] S[k, :]`` to the model of epoch n, so its share is
  ``a[n, k] sum_b S[k, b]`` over the sum of these. This is invariant to a scaling of ``a``
  (``nnls-norm``'s normalisation does not change it) and compares a dark material's large
  coefficient with its small signal, as the truth does (the reference paper, section 5.2,
  warns that the contribution is not an area fraction).

The class of an epoch is its dominant material (largest share). The confusion matrix has
one row per true class and one column per estimated class, each row divided by the number of
epochs of that true class (the reference paper's Figure 13); a class no epoch has gives a
NaN row.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError

F64 = NDArray[np.float64]


def material_shares(contribution: ArrayLike) -> F64:
    """True signal shares (N, M) from per-material contributions (N, M, B) [any unit].

    Rows with a non-finite contribution or a zero total are NaN.
    """
    c = np.asarray(contribution, dtype=np.float64)
    if c.ndim != 3:
        raise InputError(
            f"contribution must be (N epochs, M materials, B bands), got shape {c.shape}",
            field="contribution",
        )
    per_material = c.sum(axis=2)
    return _normalised(per_material)


def signal_shares(abundance: ArrayLike, signatures: ArrayLike) -> F64:
    """Estimated signal shares (N, K): ``a[n, k] sum_b S[k, b]`` normalised per epoch."""
    a = np.asarray(abundance, dtype=np.float64)
    s = np.asarray(signatures, dtype=np.float64)
    if a.ndim != 2 or s.ndim != 2 or a.shape[1] != s.shape[0]:
        raise InputError(
            f"abundance {a.shape} and signatures {s.shape} must be (N, K) and (K, B)",
            field="abundance",
        )
    return _normalised(a * s.sum(axis=1)[None, :])


def _normalised(parts: F64) -> F64:
    total = parts.sum(axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        out = parts / total
    bad = ~np.all(np.isfinite(parts), axis=1) | ~(np.abs(total[:, 0]) > 0)
    out[bad] = np.nan
    return np.asarray(out, dtype=np.float64)


def merge_columns(shares: ArrayLike, classes: ArrayLike, n_classes: int) -> F64:
    """Sum the columns of ``shares`` (N, K) into ``n_classes`` classes: column k goes to
    ``classes[k]`` (e.g. endmembers matched to materials)."""
    x = np.asarray(shares, dtype=np.float64)
    idx = np.asarray(classes, dtype=np.intp)
    if idx.shape != (x.shape[1],) or np.any(idx < 0) or np.any(idx >= n_classes):
        raise InputError(
            f"classes must give a class in [0, {n_classes}) for each of the {x.shape[1]} "
            f"columns, got {idx.tolist()}",
            field="classes",
        )
    out = np.zeros((x.shape[0], n_classes))
    for k, c in enumerate(idx):
        out[:, c] += x[:, k]
    return out


def confusion_matrix(true_shares: ArrayLike, estimated_shares: ArrayLike) -> F64:
    """Row-normalised confusion matrix (C, C) of the dominant class per epoch.

    Parameters
    ----------
    true_shares, estimated_shares
        (N, C) shares of the same C classes, in the same order. Epochs with a NaN in either
        are left out.

    Returns
    -------
    numpy.ndarray
        ``m[i, j]``: the fraction of the epochs whose true dominant class is i that were
        estimated as dominated by class j; NaN rows for classes that dominate no epoch.
    """
    t, e = _paired(true_shares, estimated_shares)
    c = t.shape[1]
    counts = np.zeros((c, c))
    np.add.at(counts, (np.argmax(t, axis=1), np.argmax(e, axis=1)), 1.0)
    rows = counts.sum(axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(rows > 0, counts / rows, np.nan)


def mean_absolute_share_error(true_shares: ArrayLike, estimated_shares: ArrayLike) -> float:
    """Mean over epochs and classes of ``|estimated - true|`` share [1] (NaN epochs left out)."""
    t, e = _paired(true_shares, estimated_shares)
    return float(np.mean(np.abs(e - t))) if t.size else float("nan")


def _paired(true_shares: ArrayLike, estimated_shares: ArrayLike) -> tuple[F64, F64]:
    t = np.asarray(true_shares, dtype=np.float64)
    e = np.asarray(estimated_shares, dtype=np.float64)
    if t.ndim != 2 or t.shape != e.shape:
        raise InputError(
            f"true and estimated shares must be (N, C) of one shape, got {t.shape} and {e.shape}",
            field="shares",
        )
    good = np.all(np.isfinite(t), axis=1) & np.all(np.isfinite(e), axis=1)
    return t[good], e[good]


def spectral_angle_rad(a: ArrayLike, b: ArrayLike) -> F64:
    """Spectral angles [rad] (K, M) between the rows of ``a`` (K, B) and ``b`` (M, B).

    ``arccos(a.b / (|a| |b|))`` (evaluated as ``2 atan2(|u - v|, |u + v|)`` of the unit
    vectors, exact to rounding also near 0): 0 for proportional signatures (Kruse et al. 1993, "The
    spectral image processing system (SIPS)", Remote Sens. Environ. 44, 145-163,
    doi:10.1016/0034-4257(93)90013-N).
    """
    x = np.atleast_2d(np.asarray(a, dtype=np.float64))
    y = np.atleast_2d(np.asarray(b, dtype=np.float64))
    if x.shape[1] != y.shape[1]:
        raise InputError(
            f"signatures of {x.shape[1]} and {y.shape[1]} bands cannot be compared",
            field="signatures",
        )
    with np.errstate(invalid="ignore", divide="ignore"):
        u = x / np.linalg.norm(x, axis=1, keepdims=True)
        v = y / np.linalg.norm(y, axis=1, keepdims=True)
    # 2 atan2(|u - v|, |u + v|) for unit vectors: accurate near 0 and pi, where arccos is not
    diff = np.linalg.norm(u[:, None, :] - v[None, :, :], axis=2)
    total = np.linalg.norm(u[:, None, :] + v[None, :, :], axis=2)
    return np.asarray(2.0 * np.arctan2(diff, total))


def match_by_angle(signatures: ArrayLike, references: ArrayLike) -> NDArray[np.intp]:
    """For each signature (K, B), the reference (M, B) of smallest spectral angle (K,)."""
    return np.asarray(np.argmin(spectral_angle_rad(signatures, references), axis=1))
