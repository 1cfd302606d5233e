"""Linear spectral unmixing: per-epoch material contributions from band reflectance factors.

The linear mixing model of the reference paper (Nussbaum et al. 2022, "Spectral light curve
simulation for parameter estimation from space debris", *Aerospace* 9, section 5.2, eq. 6;
after Keshava & Mustard 2002, doi:10.1109/79.974727) writes the band reflectance factors
``x`` of one epoch as a mixture of ``K`` endmember signatures,

    x = S a + w,

with ``S`` the (B, K) matrix whose columns are the signatures, ``a`` the contributions
("abundances") and ``w`` the noise. Here one epoch is a row: ``x`` is (N, B), ``signatures``
is (K, B) (one signature a row, so ``S = signatures.T``) and the model reads
``x[n] = a[n] @ signatures + w[n]``. ``a`` minimises ``|x - S a|`` under the constraints of the
method:

``ls``
    none (unconstrained least squares);
``nnls``
    ``a >= 0`` (Lawson & Hanson 1974, *Solving Least Squares Problems*, ch. 23,
    doi:10.1137/1.9781611971217);
``nnls-norm``
    the ``nnls`` solution divided by its sum, so that it sums to one (the variant the
    reference paper found best, section 5.2);
``fcls``
    ``a >= 0`` and ``sum(a) = 1``, the fully constrained least squares of Heinz & Chang 2001
    (doi:10.1109/36.911111).

Solver. The constrained problems are solved exactly and for all epochs at once by
enumerating the supports (the sets of non-zero contributions). The minimiser of a
non-negative least-squares problem with support ``P`` is the least-squares solution restricted
to the signatures in ``P`` (its gradient vanishes there, the Karush-Kuhn-Tucker conditions), so
it is the feasible (all >= 0) restricted solution of smallest residual; with ``sum(a) = 1``
the restricted solutions are the equality-constrained ones (one Lagrange multiplier). For
``K`` up to ``MAX_ENUMERATED_ENDMEMBERS`` the ``2**K - 1`` supports are tried, each a small
matrix product over all epochs. For more endmembers each epoch is solved by
:func:`scipy.optimize.nnls`; ``fcls`` then uses Heinz & Chang's augmented system, the
sum-to-one row appended to ``S`` with the weight ``FCLS_SUM_WEIGHT`` times the largest
signature norm, which leaves ``|sum(a) - 1|`` of the order of
``|x - S a| |S| / (weight |S|)**2`` (about 1e-8 of the residual over the signature scale).
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations
from typing import Literal, get_args

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError, did_you_mean

F64 = NDArray[np.float64]
UnmixMethod = Literal["ls", "nnls", "nnls-norm", "fcls"]
UNMIX_METHODS: tuple[str, ...] = get_args(UnmixMethod)
#: Most endmembers for which the constrained problems are solved by trying every support
#: (``2**K - 1`` of them, vectorised over the epochs); beyond, one scipy NNLS per epoch, which
#: is then the faster (10,000 epochs, 12 bands: 0.03 s against 0.15 s at K = 4, 0.43 s
#: against 0.19 s at K = 8).
MAX_ENUMERATED_ENDMEMBERS = 7
#: Weight of the sum-to-one row of ``fcls`` in the per-epoch solver, relative to the largest
#: signature norm (Heinz & Chang 2001 put its inverse, ``delta``, on the data rows instead).
FCLS_SUM_WEIGHT = 1.0e4


@dataclass(frozen=True)
class UnmixResult:
    """Contributions of the endmembers to every epoch.

    Attributes
    ----------
    abundance
        (N, K) contribution of each endmember [unit of ``x`` over unit of ``signatures``:
        m2 sr-1 for ``ls`` and ``nnls`` with signatures as band reflectances [1]; 1 for
        ``nnls-norm`` and ``fcls``, which sum to one]. NaN rows where ``x`` has a non-finite
        value, and for ``nnls-norm`` where the NNLS contributions are all zero.
    residual
        (N,) Euclidean norm of the misfit ``x - S a`` over the bands [m2 sr-1], NaN where
        ``x`` has a non-finite value. For ``nnls-norm`` it is the misfit of the NNLS fit, before
        the normalisation (the normalised contributions are fractions, not a fit of ``x``).
    method
        The method used.
    """

    abundance: F64
    residual: F64
    method: str


def _validated_samples(x: ArrayLike, name: str = "x") -> F64:
    """``x`` as a (N, B) float array; non-finite values are allowed (they mark rows)."""
    try:
        arr = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be a numeric (N, B) array: {exc}", field=name) from exc
    if arr.ndim != 2:
        hint = f" (for one spectrum use {name}[None, :])" if arr.ndim == 1 else ""
        raise InputError(
            f"{name} must be a (N, B) array of N epochs by B bands, got shape {arr.shape}{hint}",
            field=name,
        )
    if arr.shape[1] == 0:
        raise InputError(f"{name} has no bands (shape {arr.shape}); it needs B >= 1", field=name)
    return arr


def _validated_signatures(signatures: ArrayLike, n_bands: int) -> F64:
    """The (K, B) signatures, checked finite, matching ``x``'s bands and linearly independent."""
    s = _validated_samples(signatures, "signatures")
    k, b = s.shape
    if b != n_bands:
        raise InputError(
            f"signatures has {b} bands per signature (shape {s.shape}) but x has {n_bands}; "
            "give one (K, B) row per endmember in the bands of x",
            field="signatures",
        )
    if k == 0:
        raise InputError("signatures is empty; give at least one endmember", field="signatures")
    if not np.all(np.isfinite(s)):
        bad = np.argwhere(~np.isfinite(s))[0]
        raise InputError(
            f"signatures[{bad[0]}, {bad[1]}] = {s[bad[0], bad[1]]} must be finite",
            field="signatures",
        )
    if k > b:
        raise InputError(
            f"K = {k} endmembers is more than the {b} bands: the contributions are not "
            f"determined; use at most {b} signatures or more bands",
            field="signatures",
        )
    rank = int(np.linalg.matrix_rank(s))
    if rank < k:
        raise InputError(
            f"the {k} signatures are linearly dependent (rank {rank}): their contributions "
            "are not determined; drop the signatures that are mixtures of the others",
            field="signatures",
        )
    return s


def _residual_norm(x: F64, a: F64, s: F64) -> F64:
    r = x - a @ s
    return np.sqrt(np.einsum("nb,nb->n", r, r))


def _least_squares(x: F64, s: F64) -> F64:
    """Unconstrained solution ``a = x S (S^T S)^-1`` (rows), by an orthogonal solver."""
    sol, *_ = np.linalg.lstsq(s.T, x.T, rcond=None)
    return np.asarray(sol.T)


def _enumerated(x: F64, s: F64, sum_to_one: bool) -> F64:
    """Exact NNLS (or FCLS) of every row by trying all supports (see the module docstring)."""
    n, k = x.shape[0], s.shape[0]
    best_a = np.zeros((n, k))
    if sum_to_one:
        best_r = np.full(n, np.inf)
    else:
        best_r = np.einsum("nb,nb->n", x, x)  # the empty support, a = 0
    for size in range(1, k + 1):
        for support in combinations(range(k), size):
            idx = list(support)
            sp = s[idx]
            gram_inv = np.linalg.inv(sp @ sp.T)
            a = x @ (sp.T @ gram_inv)
            if sum_to_one:
                g = gram_inv.sum(axis=1)
                a += np.outer(1.0 - a.sum(axis=1), g / g.sum())
            r = x - a @ sp
            r2 = np.einsum("nb,nb->n", r, r)
            better = np.all(a >= 0.0, axis=1) & (r2 < best_r)
            if np.any(better):
                best_r[better] = r2[better]
                row = np.zeros((int(better.sum()), k))
                row[:, idx] = a[better]
                best_a[better] = row
    return best_a


def _per_row(x: F64, s: F64, sum_to_one: bool) -> F64:
    """NNLS (or Heinz & Chang's augmented FCLS) of each row with :func:`scipy.optimize.nnls`."""
    from scipy.optimize import nnls as scipy_nnls  # here: importing scipy.optimize costs ~0.3 s

    n, k = x.shape[0], s.shape[0]
    a = np.zeros((n, k))
    mat = s.T
    if sum_to_one:
        weight = FCLS_SUM_WEIGHT * float(np.max(np.linalg.norm(s, axis=1)))
        mat = np.vstack([mat, np.full((1, k), weight)])
    for i in range(n):
        rhs = np.append(x[i], weight) if sum_to_one else x[i]
        a[i], _ = scipy_nnls(mat, rhs)
    return a


def unmix(x: ArrayLike, signatures: ArrayLike, method: UnmixMethod = "fcls") -> UnmixResult:
    """Contributions of known endmembers to each epoch's band reflectance factors (eq. 6).

    Parameters
    ----------
    x
        (N, B) band reflectance factors of N epochs in B bands [m2 sr-1]. A row with a
        non-finite value gives a NaN row of the result (the other rows are unaffected).
    signatures
        (K, B) band signatures of the K endmembers, one a row (e.g. band reflectances [1]);
        finite, linearly independent, ``K <= B``.
    method
        ``"ls"`` (unconstrained), ``"nnls"`` (non-negative), ``"nnls-norm"`` (non-negative,
        then divided by the sum) or ``"fcls"`` (non-negative and summing to one; Heinz & Chang
        2001, doi:10.1109/36.911111). See the module docstring for the solver.

    Returns
    -------
    UnmixResult
        ``abundance`` (N, K) and ``residual`` (N,) [m2 sr-1], the norm of ``x - S a``.

    Raises
    ------
    InputError
        For a shape other than (N, B) and (K, B) with the same B, non-finite or linearly
        dependent signatures, ``K > B`` or an unknown method.
    """
    if method not in UNMIX_METHODS:
        raise InputError(
            f"unknown unmixing method {method!r}{did_you_mean(str(method), UNMIX_METHODS)} "
            f"(choices: {', '.join(UNMIX_METHODS)})",
            field="method",
        )
    xs = _validated_samples(x)
    s = _validated_signatures(signatures, xs.shape[1])
    good = np.all(np.isfinite(xs), axis=1)
    xg = xs[good]
    if method == "ls":
        a = _least_squares(xg, s)
    elif s.shape[0] <= MAX_ENUMERATED_ENDMEMBERS:
        a = _enumerated(xg, s, sum_to_one=method == "fcls")
    else:
        a = _per_row(xg, s, sum_to_one=method == "fcls")
    return result_rows(a, _residual_norm(xg, a, s), good, method)


def result_rows(a: F64, residual: F64, good: NDArray[np.bool_], method: str) -> UnmixResult:
    """The result of the ``good`` rows' contributions ``a`` and residuals (NaN elsewhere),
    normalised to sum to one for ``nnls-norm``."""
    if method == "nnls-norm":
        total = a.sum(axis=1, keepdims=True)
        with np.errstate(invalid="ignore", divide="ignore"):
            a = np.where(total > 0.0, a / total, np.nan)
    abundance = np.full((good.size, a.shape[1]), np.nan)
    res = np.full(good.size, np.nan)
    abundance[good] = a
    res[good] = residual
    return UnmixResult(abundance=abundance, residual=res, method=method)
