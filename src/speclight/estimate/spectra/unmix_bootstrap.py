"""Abundance uncertainties of the constrained unmixings by a parametric bootstrap.

The non-negative solvers (``nnls``, ``nnls-norm``, ``fcls``) are linear in the data only on a
fixed support (the endmembers with a non-zero contribution). Where a contribution sits near
zero, noise moves the solution from one support to another, and a standard deviation that
holds the support fixed is too small: on the calibration bench (``bench/
bench_calibration_spectra.py``) ``(estimate - truth) / std`` had a standard deviation of 1.6
(up to 5) per draw, 3 to 9 on the epochs with an endmember at the bound, and about 1 on the
others.

The parametric bootstrap (Efron & Tibshirani 1993, *An Introduction to the Bootstrap*,
ch. 6) redraws the data ``BOOTSTRAP_DRAWS`` times from the noise model around the fitted
model ``x_hat = a S`` (``x_hat + sigma * N(0, 1)``, a fixed seed so that a run repeats),
re-solves every draw with the same solver and reports, per contribution,

* the root mean square of the re-solved contributions about the estimate (their spread, and
  the bias the bound gives, as one number) as the standard deviation;
* their ``UPPER_QUANTILE`` quantile as a one-sided upper bound, the number to quote where
  the estimate is 0 (there the standard deviation is not symmetric about the truth).

All draws of all epochs are solved at once by the exact support enumeration of
:mod:`.unmixing_epochs`, each support's affine map computed once per epoch for all its draws
(chunks of ``BOOTSTRAP_CHUNK_ROWS`` epochs x draws).
"""

from __future__ import annotations

import warnings
from itertools import combinations

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.spectra.unmixing import MAX_ENUMERATED_ENDMEMBERS

F64 = NDArray[np.float64]
#: Number of redrawn data sets (the relative error of a standard deviation from n draws is
#: about 1 / sqrt(2 n): 7 % at 100).
BOOTSTRAP_DRAWS = 100
#: Seed of the redraws (a run repeats exactly).
BOOTSTRAP_SEED = 0
#: Quantile of the re-solved contributions given as the one-sided upper bound.
UPPER_QUANTILE = 0.95
#: Rows (epochs x draws) solved per call: bounds the memory of the per-epoch signatures
#: (rows x K x B floats).
BOOTSTRAP_CHUNK_ROWS = 100_000


def bootstrap_applies(method: str, n_endmembers: int) -> bool:
    """Whether :func:`bootstrap_abundance` is used: a constrained method solved by the
    vectorised enumeration (beyond ``MAX_ENUMERATED_ENDMEMBERS`` it would cost one scipy NNLS
    per epoch and draw)."""
    return method != "ls" and n_endmembers <= MAX_ENUMERATED_ENDMEMBERS


def bootstrap_abundance(
    model: F64,
    abundance: F64,
    signatures: F64,
    sigma: F64,
    method: str,
    draws: int = BOOTSTRAP_DRAWS,
    seed: int = BOOTSTRAP_SEED,
) -> tuple[F64, F64]:
    """Standard deviation and upper bound (N, K) of the contributions (module doc).

    Parameters
    ----------
    model
        (N, B) the fitted factors ``a S`` (for ``nnls-norm`` those of the NNLS fit) [m2 sr-1];
        finite rows only.
    abundance
        (N, K) the estimate [unit of the abundance].
    signatures
        (N, K, B) each epoch's band signatures.
    sigma
        (N, B) standard deviation of the factors [m2 sr-1].
    method
        ``nnls``, ``nnls-norm`` or ``fcls``.
    draws, seed
        Number of redrawn data sets and the seed of the generator.

    Returns
    -------
    std, upper
        (N, K) root mean square of the re-solved contributions about ``abundance`` and their
        ``UPPER_QUANTILE`` quantile [unit of the abundance]; NaN where every draw failed
        (``nnls-norm`` with all contributions 0).
    """
    n, k, _ = signatures.shape
    rng = np.random.default_rng(seed)
    per_chunk = max(1, BOOTSTRAP_CHUNK_ROWS // max(n, 1))
    maps = [_support_solution(signatures, list(idx), method == "fcls") for idx in _supports(k)]
    solved = []
    for start in range(0, draws, per_chunk):
        m = min(per_chunk, draws - start)
        x = model[:, None, :] + sigma[:, None, :] * rng.standard_normal((n, m, model.shape[1]))
        a = _solve(x, signatures, maps, method == "fcls")  # (N, m, K)
        if method == "nnls-norm":
            total = a.sum(axis=2, keepdims=True)
            with np.errstate(invalid="ignore", divide="ignore"):
                a = np.where(total > 0.0, a / total, np.nan)
        solved.append(a)
    re_solved = np.moveaxis(np.concatenate(solved, axis=1), 1, 0)  # (draws, N, K)
    with warnings.catch_warnings():  # an all-NaN column (nnls-norm, all zero): NaN, said
        warnings.simplefilter("ignore", RuntimeWarning)
        std = np.sqrt(np.nanmean((re_solved - abundance[None]) ** 2, axis=0))
        upper = np.nanquantile(re_solved, UPPER_QUANTILE, axis=0)
    return np.asarray(std), np.asarray(upper)


def _supports(k: int) -> list[tuple[int, ...]]:
    """Every non-empty subset of the K endmembers."""
    return [c for size in range(1, k + 1) for c in combinations(range(k), size)]


def support_map(s: F64, sum_to_one: bool) -> tuple[F64, F64]:
    """The affine map of the solution on a support, ``a_P = x M + c``: ``M`` (n, B, P) and
    ``c`` (n, P), for the signatures ``s`` (n, P, B) of the support (:mod:`.unmix_checks`)."""
    gram_inv = np.linalg.inv(np.einsum("npb,nqb->npq", s, s))
    m = np.einsum("npb,npq->nbq", s, gram_inv)
    c = np.zeros(gram_inv.shape[:2])
    if sum_to_one:
        g = gram_inv.sum(axis=2)  # (n, P)
        c = g / g.sum(axis=1, keepdims=True)
        m = m - np.einsum("npb,np->nb", s, g)[:, :, None] * c[:, None, :]
    return np.asarray(m), c


def _support_solution(s: F64, idx: list[int], sum_to_one: bool) -> tuple[list[int], F64, F64]:
    m, c = support_map(np.ascontiguousarray(s[:, idx, :]), sum_to_one)
    return idx, m, c


def _solve(x: F64, s: F64, maps: list[tuple[list[int], F64, F64]], sum_to_one: bool) -> F64:
    """Exact NNLS (FCLS) of the draws ``x`` (N, m, B) by trying every support, as
    :func:`speclight.estimate.spectra.unmixing_epochs.unmix_per_epoch` does, with each
    support's map computed once for all draws: (N, m, K)."""
    n, m, _ = x.shape
    best_a = np.zeros((n, m, s.shape[1]))
    best_r = np.full((n, m), np.inf) if sum_to_one else np.einsum("nmb,nmb->nm", x, x)
    for idx, mat, c in maps:
        a = x @ mat + c[:, None, :]  # (N, m, P)
        r = x - a @ s[:, idx, :]
        r2 = np.einsum("nmb,nmb->nm", r, r)
        better = np.all(a >= 0.0, axis=2) & (r2 < best_r)
        best_r[better] = r2[better]
        full = np.zeros((n, m, s.shape[1]))
        full[:, :, idx] = a
        best_a[better] = full[better]
    return best_a
