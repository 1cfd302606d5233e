"""Linear unmixing with band signatures that change with the epoch.

The band reflectance factor weights a material's reflectance by the detected photons of
the source at the aperture (eq. 5, docs/upsample-unmix.md), and the atmosphere changes that source's
spectral shape along a pass, so the exact signatures differ from epoch to epoch
(:mod:`speclight.estimate.spectra.endmember_spectra`). :func:`unmix_per_epoch` solves eq. 6 of
each epoch with its own signatures by the solvers of :mod:`speclight.estimate.spectra.unmixing`
(the same exact support enumeration, vectorised over the epochs; per-epoch scipy NNLS beyond
``MAX_ENUMERATED_ENDMEMBERS``; the normal equations for ``ls``).
"""

from __future__ import annotations

from itertools import combinations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError
from speclight.estimate.spectra.unmixing import (
    MAX_ENUMERATED_ENDMEMBERS,
    UNMIX_METHODS,
    UnmixMethod,
    UnmixResult,
    _per_row,
    _validated_samples,
    _validated_signatures,
    result_rows,
    unmix,
)

F64 = NDArray[np.float64]


def _enumerated_per_epoch(x: F64, s: F64, sum_to_one: bool) -> F64:
    """:func:`_enumerated` with each row's own signatures ``s`` (N, K, B), all rows at once."""
    n, k = x.shape[0], s.shape[1]
    best_a = np.zeros((n, k))
    best_r = np.full(n, np.inf) if sum_to_one else np.einsum("nb,nb->n", x, x)
    for size in range(1, k + 1):
        for support in combinations(range(k), size):
            idx = list(support)
            sp = s[:, idx, :]
            gram_inv = np.linalg.inv(np.einsum("npb,nqb->npq", sp, sp))
            a = np.einsum("np,npq->nq", np.einsum("nb,npb->np", x, sp), gram_inv)
            if sum_to_one:
                g = gram_inv.sum(axis=2)
                a += (1.0 - a.sum(axis=1))[:, None] * g / g.sum(axis=1, keepdims=True)
            r = x - np.einsum("np,npb->nb", a, sp)
            r2 = np.einsum("nb,nb->n", r, r)
            better = np.all(a >= 0.0, axis=1) & (r2 < best_r)
            best_r[better] = r2[better]
            best_a[better] = 0.0
            best_a[np.ix_(better, idx)] = a[better]
    return best_a


def unmix_per_epoch(
    x: ArrayLike, signatures: ArrayLike, method: UnmixMethod = "fcls"
) -> UnmixResult:
    """:func:`unmix` with signatures that change with the epoch.

    ``signatures`` (N, K, B): epoch n is unmixed with ``signatures[n]`` (the band
    signatures weighted by that epoch's source spectrum, which the atmosphere changes along
    a pass; :mod:`speclight.estimate.inputs.source_spectrum`), by the same solvers, vectorised over
    the epochs up to ``MAX_ENUMERATED_ENDMEMBERS``. The signatures are checked as
    :func:`unmix` checks them on their mean over the epochs; epochs whose ``x`` or
    signatures are not finite give NaN rows. (K, B) signatures: :func:`unmix` itself.
    """
    s = np.asarray(signatures, dtype=np.float64)
    if s.ndim != 3:
        return unmix(x, s, method)
    if method not in UNMIX_METHODS:
        return unmix(x, s[0], method)  # its message
    xs = _validated_samples(x)
    if s.shape[0] != xs.shape[0]:
        raise InputError(
            f"per-epoch signatures {s.shape} must be (N, K, B) with N = {xs.shape[0]} epochs",
            field="signatures",
        )
    good = np.all(np.isfinite(xs), axis=1) & np.all(np.isfinite(s), axis=(1, 2))
    if np.any(good):
        _validated_signatures(s[good].mean(axis=0), xs.shape[1])
    xg, sg = xs[good], s[good]
    if method == "ls":
        rhs = np.einsum("nb,nkb->nk", xg, sg)[:, :, None]
        a = np.linalg.solve(np.einsum("npb,nqb->npq", sg, sg), rhs)[:, :, 0]
    elif s.shape[1] <= MAX_ENUMERATED_ENDMEMBERS:
        a = _enumerated_per_epoch(xg, sg, sum_to_one=method == "fcls")
    else:
        a = np.stack(
            [_per_row(xg[i : i + 1], sg[i], method == "fcls")[0] for i in range(len(xg))]
        ).reshape(len(xg), s.shape[1])
    r = xg - np.einsum("nk,nkb->nb", a, sg)
    return result_rows(a, np.sqrt(np.einsum("nb,nb->n", r, r)), good, method)
