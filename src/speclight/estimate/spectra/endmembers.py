"""Endmember extraction: material signatures found in the measured band reflectance factors.

Where no library of signatures matches the target, the signatures are taken from the data
(reference paper, Nussbaum et al. 2022, section 5.2 and Figure 14, where ATGP did better than
PCA). The samples are the rows of ``x`` (N epochs by B bands [m2 sr-1]); rows with a
non-finite value are left out and the returned indices count the rows of ``x`` as given.

``atgp``
    Automatic target generation process (Ren & Chang 2003, "Automatic spectral target
    recognition in hyperspectral imagery", IEEE TAES 39, 1232-1249,
    doi:10.1109/TAES.2003.1261119): the sample of largest norm, then K - 1 times the sample of
    largest norm after the orthogonal projection ``I - U (U^T U)^-1 U^T`` away from the
    samples ``U`` chosen so far. Implemented with an orthonormal basis of ``U`` grown one
    Gram-Schmidt step at a time, so the projection of all samples costs O(N B) per step.
``pca``
    Principal component analysis: the mean ``m`` of the samples and the K - 1 leading
    principal directions ``v_i`` of the centred samples (right singular vectors, each signed
    so that its entry of largest magnitude is positive), returned as the K signatures
    ``m`` and ``m + sigma_i v_i``, with ``sigma_i`` the standard deviation of the samples along
    ``v_i`` (population, divided by N). They span the same affine subspace as the data's
    K - 1 leading components, so unmixing with them gives principal-component coordinates;
    like the paper found, they are linear combinations of the true signatures, not the
    signatures themselves. No sample is picked (``indices`` is None).
``nfindr``
    N-FINDR (Winter 1999, "N-FINDR: an algorithm for fast autonomous spectral end-member
    determination in hyperspectral data", Proc. SPIE 3753, doi:10.1117/12.366289): the
    samples projected onto the K - 1 leading principal components (as for ``pca``); starting
    from the ATGP samples, each vertex in turn is replaced by the sample that makes the
    simplex volume ``|det [1 ... 1; y_1 ... y_K]| / (K - 1)!`` largest, if that is larger, and
    the sweeps are repeated until no replacement increases the volume. The volume with one
    vertex replaced is linear in the new vertex (cofactor expansion along its column), so each
    trial over all samples is one (N, K) product.
``purest``
    The vertices of the shapes (each sample divided by its band sum) of the samples above
    the noise, by successive projections that weigh the noise, each averaged with the shapes
    within its noise (:mod:`speclight.estimate.spectra.endmember_purest`): the purest
    epochs, not the brightest; it says when fewer shapes than endmembers asked differ above
    the noise, when two have the same shape within it, and when an endmember rests on fewer
    than 3 epochs.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import factorial
from numbers import Integral
from typing import Literal, get_args

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError, did_you_mean
from speclight.estimate.spectra.endmember_purest import purest
from speclight.estimate.spectra.unmixing import _validated_samples

F64 = NDArray[np.float64]
EndmemberMethod = Literal["purest", "atgp", "pca", "nfindr"]
ENDMEMBER_METHODS: tuple[str, ...] = get_args(EndmemberMethod)
#: A residual norm below this fraction of the largest sample norm counts as zero in ATGP:
#: the samples then span fewer than K directions.
ATGP_RANK_TOLERANCE = 1e-10
#: N-FINDR accepts a replacement only if it grows the volume by more than this fraction
#: (round-off must not make two equal volumes swap back and forth).
NFINDR_RELATIVE_GAIN = 1e-12
#: Most replacements N-FINDR makes before it stops (each one strictly grows the volume, so
#: the loop ends anyway; the cap bounds the time on pathological data).
NFINDR_MAX_SWAPS = 1000


@dataclass(frozen=True)
class EndmemberResult:
    """Signatures extracted from the samples.

    Attributes
    ----------
    signatures
        (K, B) endmember signatures, one a row [unit of ``x``, m2 sr-1].
    indices
        (K,) rows of ``x`` taken as the signatures (``atgp``, ``nfindr``; in the order
        chosen), or None for ``pca``, whose signatures are not samples.
    method
        The method used.
    volumes
        ``nfindr`` only: the simplex volume in the principal-component space at the ATGP start
        and after each replacement [(m2 sr-1)**(K-1)], non-decreasing; None otherwise.
    notes
        What the extraction found doubtful (e.g. fewer pure epochs than endmembers).
    """

    signatures: F64
    indices: NDArray[np.intp] | None
    method: str
    volumes: F64 | None = None
    notes: tuple[str, ...] = ()


def _checked_k(k: object, n_samples: int, n_bands: int, method: str) -> int:
    if isinstance(k, bool) or not isinstance(k, Integral):
        raise InputError(f"k = {k!r} must be an integer number of endmembers", field="k")
    kk = int(k)
    least = 2 if method == "nfindr" else 1
    if kk < least:
        why = " (a simplex needs at least 2 vertices)" if method == "nfindr" else ""
        raise InputError(f"k = {kk} must be >= {least} for {method}{why}", field="k")
    if kk > n_bands:
        raise InputError(
            f"k = {kk} endmembers is more than the {n_bands} bands of x; ask for k <= {n_bands}",
            field="k",
        )
    if kk > n_samples:
        raise InputError(
            f"k = {kk} endmembers is more than the {n_samples} samples of x with finite "
            f"values; ask for k <= {n_samples}",
            field="k",
        )
    return kk


def _atgp(x: F64, k: int) -> NDArray[np.intp]:
    """Ren & Chang's ATGP on finite samples: K row indices, in the order chosen."""
    residual = x.copy()
    scale = float(np.sqrt(np.max(np.einsum("nb,nb->n", x, x))))
    chosen = np.empty(k, dtype=np.intp)
    for j in range(k):
        norm2 = np.einsum("nb,nb->n", residual, residual)
        i = int(np.argmax(norm2))
        if not np.sqrt(norm2[i]) > ATGP_RANK_TOLERANCE * scale:
            raise InputError(
                f"the finite samples of x span only {j} linearly independent directions; "
                f"ask for k <= {j}",
                field="k",
            )
        chosen[j] = i
        q = residual[i] / np.sqrt(norm2[i])  # new orthonormal direction of span(U)
        residual -= np.outer(residual @ q, q)
    return chosen


def _principal_components(x: F64, n: int) -> tuple[F64, F64, F64]:
    """Mean (B,), the ``n`` leading unit directions (n, B) and standard deviations (n,)."""
    mean = x.mean(axis=0)
    _, sv, vt = np.linalg.svd(x - mean, full_matrices=False)
    directions = vt[:n].copy()
    lead = np.argmax(np.abs(directions), axis=1)
    directions *= np.where(directions[np.arange(n), lead] < 0.0, -1.0, 1.0)[:, None]
    return mean, directions, sv[:n] / np.sqrt(x.shape[0])


def _cofactors(vertices: F64, j: int) -> F64:
    """Cofactors of column ``j`` of the (K, K) matrix ``vertices``: det = cof @ column."""
    k = vertices.shape[0]
    cof = np.empty(k)
    for r in range(k):
        minor = np.delete(np.delete(vertices, r, axis=0), j, axis=1)
        cof[r] = (-1.0) ** (r + j) * (np.linalg.det(minor) if k > 1 else 1.0)
    return cof


def _nfindr(x: F64, k: int) -> tuple[NDArray[np.intp], F64]:
    """Winter's N-FINDR from the ATGP start: K row indices and the volume history."""
    mean, directions, _ = _principal_components(x, k - 1)
    aug = np.hstack([np.ones((x.shape[0], 1)), (x - mean) @ directions.T])  # (N, K): [1, y]
    norm = 1.0 / factorial(k - 1)
    chosen = _atgp(x, k)
    volume = abs(float(np.linalg.det(aug[chosen].T))) * norm
    volumes = [volume]
    improved = True
    while improved and len(volumes) <= NFINDR_MAX_SWAPS:
        improved = False
        for j in range(k):
            trial = np.abs(aug @ _cofactors(aug[chosen].T, j)) * norm
            i = int(np.argmax(trial))
            if trial[i] > volume * (1.0 + NFINDR_RELATIVE_GAIN) and i not in chosen:
                chosen[j] = i
                volume = float(trial[i])
                volumes.append(volume)
                improved = True
    return chosen, np.asarray(volumes)


def extract_endmembers(
    x: ArrayLike, k: int, method: EndmemberMethod = "purest", sigma: ArrayLike | None = None
) -> EndmemberResult:
    """Extract ``k`` endmember signatures from the samples ``x``.

    Parameters
    ----------
    x
        (N, B) band reflectance factors of N epochs in B bands [m2 sr-1]; rows with a
        non-finite value are left out.
    k
        Number of endmembers, ``1 <= k <= min(B, number of finite rows)`` (``k >= 2`` for
        ``nfindr``).
    method
        ``"purest"`` (default: the vertices of the samples' shapes above the noise,
        :mod:`.endmember_purest`; the best on the calibration bench, within 3 deg of the
        true signatures in all 60 draws where ATGP was in none), ``"atgp"`` (Ren & Chang
        2003, doi:10.1109/TAES.2003.1261119), ``"pca"`` (mean and K - 1 principal
        directions) or ``"nfindr"`` (Winter 1999, doi:10.1117/12.366289); see the module
        docstring for how each forms the signatures.
    sigma
        (N, B) standard deviation of ``x`` [m2 sr-1], for ``purest`` (None: unknown).

    Returns
    -------
    EndmemberResult
        ``signatures`` (K, B) [m2 sr-1], ``indices`` (K,) of the rows of ``x`` chosen (None
        for ``pca``) and, for ``nfindr``, the simplex ``volumes`` along the iterations.

    Raises
    ------
    InputError
        For ``x`` not (N, B), an unknown method, a ``k`` out of range, or samples that span
        fewer than ``k`` directions (``atgp``, ``nfindr``).
    """
    if method not in ENDMEMBER_METHODS:
        raise InputError(
            f"unknown endmember method {method!r}{did_you_mean(str(method), ENDMEMBER_METHODS)}"
            f" (choices: {', '.join(ENDMEMBER_METHODS)})",
            field="method",
        )
    xs = _validated_samples(x)
    rows = np.flatnonzero(np.all(np.isfinite(xs), axis=1))
    xg = xs[rows]
    kk = _checked_k(k, len(rows), xs.shape[1], method)
    if method == "pca":
        mean, directions, sigma = _principal_components(xg, kk - 1)
        signatures = np.vstack([mean, mean + sigma[:, None] * directions])
        return EndmemberResult(signatures=signatures, indices=None, method=method)
    volumes = None
    if method == "purest":
        noise = None if sigma is None else np.asarray(sigma, dtype=np.float64)[rows]
        if noise is not None and not np.all(np.isfinite(noise)):
            noise = None
        picked, signatures, notes = purest(xg, kk, noise, _atgp)
        return EndmemberResult(signatures, rows[picked], method, notes=notes)
    if method == "atgp":
        chosen = _atgp(xg, kk)
    else:
        chosen, volumes = _nfindr(xg, kk)
    return EndmemberResult(
        signatures=xg[chosen].copy(), indices=rows[chosen], method=method, volumes=volumes
    )
