"""Comparing estimated with true contributions: confusion matrix, errors, spectral angle.

Plain arrays in, plain arrays out. The compared quantities are **shares**: the fractions
``g_k / sum(g)`` of an epoch's contributions (N, C), true ones from the ground truth
(:func:`speclight.estimate.spectra.ground_truth.true_contributions` and ``fractions``), estimated
ones from the unmixing (``nnls-norm`` returns them; other methods' contributions divided by
their sum). Extracted endmembers, whose signatures are reflectance factors of arbitrary
scale, are first put in the units of reference signatures (:func:`in_reference_units`) and
summed into the classes they are matched to (:func:`merge_columns`, :func:`match_by_angle`).

The class of an epoch is its dominant material (largest share). The confusion matrix has
one row per true class and one column per estimated class: counts, or each row divided by
the number of epochs of that true class (the reference paper's Figure 13); a class no
epoch has gives a NaN row.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError

F64 = NDArray[np.float64]


def in_reference_units(abundance: ArrayLike, signatures: ArrayLike, references: ArrayLike) -> F64:
    """Contributions (N, K) re-expressed in units of reference signatures.

    Endmember k contributes ``a[n, k] S[k]`` to epoch n; in units of the reference
    ``R[k]`` (B,) that is ``a[n, k] S[k] . R[k] / |R[k]|^2`` (the projection, exact when
    ``S[k]`` is proportional to ``R[k]``). Extracted signatures (reflectance factors of an
    epoch, of arbitrary scale) become comparable with the true contributions computed with
    the same references (:func:`speclight.estimate.spectra.ground_truth.true_contributions`).
    """
    a = np.asarray(abundance, dtype=np.float64)
    s = np.asarray(signatures, dtype=np.float64)
    r = np.asarray(references, dtype=np.float64)
    if a.ndim != 2 or s.shape != r.shape or s.ndim != 2 or a.shape[1] != s.shape[0]:
        raise InputError(
            f"abundance {a.shape}, signatures {s.shape} and references {r.shape} must be "
            "(N, K), (K, B) and (K, B)",
            field="abundance",
        )
    return np.asarray(a * (np.sum(s * r, axis=1) / np.sum(r * r, axis=1))[None, :])


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


def confusion_matrix(
    true_shares: ArrayLike, estimated_shares: ArrayLike, normalise: bool = True
) -> F64:
    """Confusion matrix (C, C) of the dominant class per epoch, rows true, columns estimated.

    Parameters
    ----------
    true_shares, estimated_shares
        (N, C) shares of the same C classes, in the same order. Epochs with a NaN in either
        are left out.
    normalise
        Divide each row by its count (the reference paper's Figure 13), else the counts.

    Returns
    -------
    numpy.ndarray
        ``m[i, j]``: the number of the epochs whose true dominant class is i that were
        estimated as dominated by class j, or (``normalise``) their fraction of the row,
        with NaN rows for classes that dominate no epoch.
    """
    t, e = _paired(true_shares, estimated_shares)
    c = t.shape[1]
    counts = np.zeros((c, c))
    np.add.at(counts, (np.argmax(t, axis=1), np.argmax(e, axis=1)), 1.0)
    if not normalise:
        return counts
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
