"""What an unmixing can say about itself: abundance uncertainties, misfit against the noise,
conditioning; :func:`with_checks` puts them in the ABUND.nc dataset.

**Uncertainties.** On its support ``P`` (the endmembers with a non-zero contribution) every
solver of :mod:`.unmixing` is a linear function of the epoch's factors ``x``:
``a_P = x S_P^T G`` with ``G = (S_P S_P^T)^-1`` for ``ls`` and ``nnls``, plus the Lagrange
term ``(1 - x S_P^T g) g^T / (1^T g)`` (``g = G 1``) for ``fcls``. With the noise covariance
``Sigma = diag(sigma^2)`` of ``x`` the covariance of ``a_P`` is ``M^T Sigma M`` for that
linear map ``M`` (the sandwich form: the solvers are unweighted). ``nnls-norm`` divides by the
sum ``s``: its Jacobian ``(I - a 1^T) / s`` carries the covariance over. That standard
deviation holds the support fixed; it is exact for ``ls`` and is what ``abundance_std`` gives
there (and beyond ``MAX_ENUMERATED_ENDMEMBERS``, where an endmember at the bound gets the
standard deviation of the unconstrained fit of all ``K``). Near a bound noise changes the
support, so for the constrained methods ``abundance_std`` and the one-sided upper bound
``abundance_upper`` come from the parametric bootstrap of :mod:`.unmix_bootstrap`.

**Misfit.** ``chi2 = sum_j ((x - S a)_j / sigma_j)^2`` has ``B - |P|`` degrees of freedom
(``B - |P| + 1`` for ``fcls``, whose sum-to-one costs one parameter) where the endmembers
explain the data. An epoch with ``P(chi2) < MISFIT_P_VALUE`` is marked; more marked epochs
than chance gives means that the endmembers do not explain the data: one is missing, or a
signature is wrong (Keshava & Mustard 2002, doi:10.1109/79.974727, sec. "residual").

**Conditioning.** The condition number of the signature matrix, the factor by which relative
noise in ``x`` can grow in the contributions (Golub & Van Loan, *Matrix Computations*, 4th
ed., sec. 5.3.8).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from speclight.estimate.spectra.unmix_bootstrap import (
    UPPER_QUANTILE,
    bootstrap_abundance,
    bootstrap_applies,
    support_map,
)

F64 = NDArray[np.float64]
#: An epoch's misfit is marked when its chi-square is this improbable under the noise alone.
MISFIT_P_VALUE = 1e-3
#: The whole set is said not to be explained when the marked epochs are this improbable
#: (binomial tail of the count of marked epochs at rate MISFIT_P_VALUE).
SET_P_VALUE = 1e-3
#: Condition number of the signatures above which ``unmix`` warns.
CONDITION_WARNING = 1.0e3


@dataclass(frozen=True)
class UnmixChecks:
    """Per-epoch uncertainties and misfit of an unmixing.

    Attributes
    ----------
    abundance_std
        (N, K) standard deviation of each contribution [unit of the abundance].
    chi2
        (N,) chi-square of the misfit against the noise [1].
    dof
        (N,) its degrees of freedom.
    misfit
        (N,) whether ``P(chi2) < MISFIT_P_VALUE``.
    condition_number
        Condition number of the (mean) signature matrix [1].
    abundance_upper
        (N, K) one-sided upper bound (the ``UPPER_QUANTILE`` quantile of the bootstrap,
        :mod:`.unmix_bootstrap`) [unit of the abundance]; None where not bootstrapped
        (``ls``, more than ``MAX_ENUMERATED_ENDMEMBERS`` endmembers).
    """

    abundance_std: F64
    chi2: F64
    dof: NDArray[np.int64]
    misfit: NDArray[np.bool_]
    condition_number: float
    abundance_upper: F64 | None = None

    def notes(self) -> list[str]:
        """Sentences for a user: a missing endmember, bad conditioning."""
        out = []
        ok = np.isfinite(self.chi2)
        n, marked = int(ok.sum()), int(self.misfit[ok].sum())
        if n and marked_beyond_chance(marked, n):
            share = np.nansum(self.chi2[self.misfit]) / max(np.nansum(self.chi2), 1e-300)
            out.append(
                f"{marked} of {n} epochs misfit beyond the noise (chi-square P < "
                f"{MISFIT_P_VALUE:g}, {MISFIT_P_VALUE * n:.2g} expected by chance; they hold "
                f"{100 * share:.0f} % of the total chi-square): the endmembers do not explain "
                "the data, an endmember is missing or a signature is wrong (see misfit(time))"
            )
        if self.condition_number > CONDITION_WARNING:
            out.append(
                f"the endmember signatures are nearly dependent (condition number "
                f"{self.condition_number:.3g}): relative noise grows up to that much in the "
                "contributions (see abundance_std)"
            )
        return out


def marked_beyond_chance(marked: int, n: int) -> bool:
    """Whether ``marked`` of ``n`` epochs at rate MISFIT_P_VALUE is improbable (binomial)."""
    from scipy.stats import binom

    return bool(marked > 0 and binom.sf(marked - 1, n, MISFIT_P_VALUE) < SET_P_VALUE)


def _covariance(s: F64, sigma: F64, sum_to_one: bool) -> F64:
    """Covariance (n, P, P) of the support solution: ``M^T diag(sigma^2) M``."""
    m, _ = support_map(s, sum_to_one)
    return np.asarray(np.einsum("nbp,nb,nbq->npq", m, sigma**2, m))


def unmix_checks(x: F64, abundance: F64, signatures: F64, sigma: F64, method: str) -> UnmixChecks:
    """Uncertainties and misfit of an unmixing (module doc).

    Parameters
    ----------
    x
        (N, B) band reflectance factors [m2 sr-1].
    abundance
        (N, K) the contributions found (NaN rows where not unmixed).
    signatures
        (K, B) or (N, K, B) band signatures.
    sigma
        (N, B) standard deviation of ``x`` [m2 sr-1].
    method
        The unmixing method (``ls``, ``nnls``, ``nnls-norm``, ``fcls``).
    """
    n, k = abundance.shape
    s = np.asarray(signatures, dtype=np.float64)
    if s.ndim == 2:
        s = np.broadcast_to(s, (n, *s.shape))
    ok = np.all(np.isfinite(abundance), axis=1) & np.all(np.isfinite(sigma), axis=1)
    ok &= np.all(np.isfinite(x), axis=1) & np.all(sigma > 0, axis=1)
    std = np.full((n, k), np.nan)
    chi2 = np.full(n, np.nan)
    dof = np.zeros(n, dtype=np.int64)
    sum_to_one = method == "fcls"
    raw = abundance
    if method == "nnls-norm":  # back to the NNLS contributions: the fit of x
        raw = _nnls_of_normalised(x, abundance, s)
    full = _covariance(s[ok], sigma[ok], sum_to_one)
    if method == "nnls-norm":
        full = _normalised(full, raw[ok])
    std[ok] = np.sqrt(np.diagonal(full, axis1=1, axis2=2))
    support = np.abs(raw) > 0 if method != "ls" else np.ones((n, k), dtype=bool)
    patterns = {tuple(p) for p in support[ok]}
    for pattern in patterns:
        idx = np.flatnonzero(pattern)
        rows = ok & np.all(support == np.asarray(pattern), axis=1)
        if idx.size == 0 or not np.any(rows):
            continue
        cov = _covariance(s[rows][:, idx, :], sigma[rows], sum_to_one)
        if method == "nnls-norm":
            cov = _normalised(cov, raw[rows][:, idx])
        block = std[rows]
        block[:, idx] = np.sqrt(np.diagonal(cov, axis1=1, axis2=2))
        std[rows] = block
        dof[rows] = x.shape[1] - idx.size + (1 if sum_to_one else 0)
    resid = x - np.einsum("nk,nkb->nb", np.where(ok[:, None], raw, 0.0), s)
    chi2[ok] = np.sum((resid[ok] / sigma[ok]) ** 2, axis=1)
    misfit = np.zeros(n, dtype=bool)
    from scipy.stats import chi2 as chi2_dist

    has_dof = ok & (dof > 0)
    misfit[has_dof] = chi2_dist.sf(chi2[has_dof], dof[has_dof]) < MISFIT_P_VALUE
    mean_s = s[ok].mean(axis=0) if np.any(ok) else s[0]
    upper = None
    if bootstrap_applies(method, k) and np.any(ok):
        upper = np.full((n, k), np.nan)
        model = x[ok] - resid[ok]
        std[ok], upper[ok] = bootstrap_abundance(
            model, abundance[ok], np.ascontiguousarray(s[ok]), sigma[ok], method
        )
    return UnmixChecks(std, chi2, dof, misfit, condition_number(mean_s), upper)


def _nnls_of_normalised(x: F64, fractions: F64, s: F64) -> F64:
    """The NNLS contributions behind ``nnls-norm`` fractions: the fractions times the
    least-squares scale ``c = x . y / |y|^2`` of ``y = fractions @ S`` (the NNLS solution is
    that scale times its normalised form)."""
    y = np.einsum("nk,nkb->nb", np.nan_to_num(fractions), s)
    with np.errstate(invalid="ignore", divide="ignore"):
        c = np.einsum("nb,nb->n", np.nan_to_num(x), y) / np.einsum("nb,nb->n", y, y)
    return np.asarray(fractions * c[:, None])


def _normalised(cov: F64, a: F64) -> F64:
    """Covariance of ``a / sum(a)`` from that of ``a`` (n, P, P): Jacobian ``(I - f 1^T)/s``."""
    with np.errstate(invalid="ignore", divide="ignore"):
        total = a.sum(axis=1)
        f = a / total[:, None]
    p = a.shape[1]
    jac = (np.eye(p)[None] - f[:, :, None] * np.ones((1, 1, p))) / total[:, None, None]
    return np.asarray(np.einsum("nij,njk,nlk->nil", jac, cov, jac))


def condition_number(signatures: F64) -> float:
    """2-norm condition number of the (K, B) signature matrix [1]."""
    sv = np.linalg.svd(np.asarray(signatures, dtype=np.float64), compute_uv=False)
    return float(sv[0] / sv[-1]) if sv[-1] > 0 else float("inf")


def with_checks(
    ds: xr.Dataset,
    x: np.ndarray,
    abundance: np.ndarray,
    signatures: np.ndarray,
    sigma: np.ndarray | None,
    method: str,
) -> xr.Dataset:
    """``ds`` with ``abundance_std``, ``chi2``, ``misfit`` (:mod:`.unmix_checks`) where the
    noise is known, the attribute ``notes`` and a warning per note."""
    notes: list[str] = []
    if sigma is None:
        notes.append(
            "the noise of the factors is unknown (no sigma in the data, no scenario): no "
            "uncertainties and no test of the residuals against the noise"
        )
        cond = condition_number(np.asarray(ds["endmember_signature"].values))
        ds.attrs["condition_number"] = cond
    else:
        checks = unmix_checks(x, abundance, signatures, sigma, method)
        ds["abundance_std"] = (
            ("time", "endmember"),
            checks.abundance_std,
            {
                "units": ds["abundance"].attrs["units"],
                "long_name": "standard deviation of abundance (parametric bootstrap for "
                "nnls, nnls-norm, fcls; noise propagated for ls)",
            },
        )
        if checks.abundance_upper is not None:
            ds["abundance_upper"] = (
                ("time", "endmember"),
                checks.abundance_upper,
                {
                    "units": ds["abundance"].attrs["units"],
                    "long_name": f"one-sided upper bound of abundance ({UPPER_QUANTILE:g} "
                    "quantile of the bootstrap; the value to quote where abundance is 0)",
                },
            )
        ds["chi2"] = (
            "time",
            checks.chi2,
            {"units": "1", "long_name": "chi-square of the misfit against the noise"},
        )
        ds["chi2_dof"] = ("time", checks.dof, {"units": "1", "long_name": "its degrees of freedom"})
        ds["misfit"] = (
            "time",
            checks.misfit.astype(np.int8),
            {"units": "1", "long_name": f"1 where P(chi2) < {MISFIT_P_VALUE:g}"},
        )
        ds.attrs["condition_number"] = checks.condition_number
        notes += checks.notes()
    if ds.attrs["condition_number"] > CONDITION_WARNING and sigma is None:
        notes.append(
            f"the endmember signatures are nearly dependent (condition number "
            f"{ds.attrs['condition_number']:.3g})"
        )
    for note in notes:
        warnings.warn(note, stacklevel=2)
    ds.attrs["notes"] = "; ".join(notes) if notes else "ok"
    return ds
