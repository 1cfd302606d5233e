"""``purest``: endmembers from the purest epochs, not the brightest.

A band reflectance factor is a non-negative mixture ``x = sum_k g_k s_k``; its brightness
``sum_j x_j`` says how much is seen, its shape ``x / sum_j x_j`` what. ATGP on ``x`` itself
takes the sample of largest norm first, a glint, whatever its mixture (issue 25: on the
four-material cube 25 deg from the true spectra where the purest epochs were 0-7 deg). Here:

1. samples too noisy to have a shape are left out: signal-to-noise ``|x| / |sigma|`` below
   ``PUREST_MIN_SNR`` (without a noise estimate: a norm below ``PUREST_MIN_BRIGHTNESS`` of the
   90th percentile of the norms);
2. every sample is normalised to unit band sum, which puts the pure samples at the vertices
   of the simplex of shapes (Keshava & Mustard 2002, doi:10.1109/79.974727); the vertices are
   found by successive projections, ATGP (Ren & Chang 2003, doi:10.1109/TAES.2003.1261119) on
   the shapes, the successive projection algorithm of normalised data (Gillis & Vavasis 2014,
   doi:10.1109/TPAMI.2013.226);
3. with a noise estimate the projections weigh the noise. Every shape is first replaced by
   its local mean, the inverse-variance mean of the shapes within its noise (mean squared
   normalised distance below ``PUREST_CLUSTER_CHI2``): ten pure epochs of one material make
   one vertex with a tenth of the noise variance. The next vertex is the local mean of
   largest residual after the projection away from the chosen ones, among those whose
   residual is significant: chi-square ``sum (r / sigma_r)^2`` with ``B - j`` degrees of
   freedom beyond its ``1 - PUREST_DISTINCT_P / N`` quantile, ``sigma_r`` from the noise of
   the mean and that of the chosen signatures it is expanded on. Each signature is the
   inverse-variance mean of the shapes within the noise of its pick, times their median
   brightness. Plain ATGP on the shapes took the noisy shape of a dark epoch (a shape's noise
   is its noise over its small band sum) before a bright material 1.3 deg from another (the
   bench: 32 % -> 100 % of draws within 3 deg).

It says when the answer is doubtful: where no single shape's residual is significant any
more after ``j`` vertices (the test on the shapes themselves, not on their local means,
which average over mixtures where the noise is large), only ``j`` shapes are distinct above
the noise (two materials of nearly the same shape, or fewer materials than endmembers
asked); where two signatures have the same shape within their noise; and where a signature
rests on fewer than ``PUREST_MIN_EPOCHS`` epochs (the data may hold fewer pure epochs than
endmembers asked).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]
#: Least signal-to-noise ratio ``|x| / |sigma|`` of a sample whose shape is used (the
#: significance test of step 3 weighs the noise of the rest; 5 kept the pure epochs of a dark
#: material that 10 dropped, on the bench).
PUREST_MIN_SNR = 5.0
#: Without noise estimates: least norm, as a fraction of the 90th percentile of the norms.
PUREST_MIN_BRIGHTNESS = 0.1
#: A sample belongs to a chosen shape when its mean squared normalised distance is below this.
PUREST_CLUSTER_CHI2 = 2.0
#: Fewest epochs a signature should rest on before it is called supported.
PUREST_MIN_EPOCHS = 3
#: Most samples among which each sample's neighbours within its noise are sought (the cost
#: grows as samples x neighbours x bands).
PUREST_NEIGHBOURS = 5000
#: Pairs in one block of the neighbour search (8 MB per temporary array).
PUREST_CHUNK = 1_000_000
#: Probability that noise alone makes any of the samples' residuals significant (divided by
#: the number of samples for each one: Bonferroni).
PUREST_DISTINCT_P = 1e-3


def purest(
    x: F64, k: int, sigma: F64 | None, atgp: object
) -> tuple[NDArray[np.intp], F64, tuple[str, ...]]:
    """Rows chosen, signatures (K, B) [unit of ``x``] and notes (module doc).

    ``x`` (N, B) finite samples, ``sigma`` (N, B) their noise or None, ``atgp`` the ATGP
    of :mod:`.endmembers` (``atgp(samples, k) -> rows``), used without a noise estimate.
    """
    total = x.sum(axis=1)
    norm = np.linalg.norm(x, axis=1)
    if sigma is not None:
        keep = (norm / np.sqrt(np.sum(sigma**2, axis=1)) >= PUREST_MIN_SNR) & (total > 0)
    else:
        keep = (norm >= PUREST_MIN_BRIGHTNESS * np.percentile(norm, 90)) & (total > 0)
    rows = np.flatnonzero(keep)
    if rows.size < k:
        rows = np.flatnonzero(total > 0)
    shapes = x / total[:, None]
    if sigma is None:
        chosen = rows[atgp(shapes[rows], k)]  # type: ignore[operator]
        return chosen, x[chosen].copy(), ()
    shape_sigma = sigma[rows] / np.abs(total[rows])[:, None]
    local = _local_means(shapes[rows], shape_sigma)
    picked, means, mean_sigma, members, distinct = _vertices(shapes[rows], shape_sigma, k, local)
    scale = np.array([np.median(total[rows][m]) for m in members])
    notes = _notes([m.size for m in members], distinct, k, means, mean_sigma)
    return rows[picked], means * scale[:, None], notes


def _local_means(shapes: F64, sigma: F64) -> tuple[F64, F64]:
    """Each shape's inverse-variance mean with the shapes within its noise (N, B), and its
    standard deviation (N, B).

    The neighbours are sought among at most ``PUREST_NEIGHBOURS`` evenly spaced samples, with
    the noise written as a per-sample scale times one band profile, ``sigma_ib = c_i p_b``
    (``c_i`` the sample's root mean square noise, ``p_b`` the median profile), so that the
    distances of all pairs are one matrix product; the means use every band's own noise.
    """
    n, b = shapes.shape
    ref = np.unique(np.linspace(0, n - 1, min(n, PUREST_NEIGHBOURS)).astype(np.intp))
    scale = np.sqrt(np.mean(sigma**2, axis=1))
    profile = np.sqrt(np.median((sigma / scale[:, None]) ** 2, axis=0))
    white = shapes / profile
    norm2 = np.einsum("nb,nb->n", white, white)
    w_ref = 1.0 / sigma[ref] ** 2
    mean = np.empty_like(shapes)
    std = np.empty_like(shapes)
    chunk = max(1, PUREST_CHUNK // len(ref))
    for start in range(0, n, chunk):
        blk = slice(start, start + chunk)
        dist2 = norm2[blk, None] + norm2[None, ref] - 2.0 * white[blk] @ white[ref].T
        d2 = dist2 / (b * (scale[blk, None] ** 2 + scale[None, ref] ** 2))
        near = (d2 < PUREST_CLUSTER_CHI2).astype(np.float64)
        own = 1.0 / sigma[blk] ** 2  # the shape itself (once more if among ``ref``: harmless)
        wsum = near @ w_ref + own
        mean[blk] = (near @ (w_ref * shapes[ref]) + own * shapes[blk]) / wsum
        std[blk] = 1.0 / np.sqrt(wsum)
    return mean, std


def _cluster(shapes: F64, sigma: F64, i: int) -> tuple[F64, F64, NDArray[np.intp]]:
    """Inverse-variance mean (B,) of the shapes within the noise of shape ``i``, its
    standard deviation (B,) and the members."""
    d2 = np.mean((shapes - shapes[i]) ** 2 / (sigma**2 + sigma[i] ** 2), axis=1)
    member = np.flatnonzero(d2 < PUREST_CLUSTER_CHI2)
    w = 1.0 / sigma[member] ** 2
    return (shapes[member] * w).sum(axis=0) / w.sum(axis=0), 1.0 / np.sqrt(w.sum(axis=0)), member


def _significant_residual(
    shapes: F64, sigma: F64, means: F64, mean_sigma: F64
) -> tuple[F64, NDArray[np.bool_]]:
    """Squared norm (N,) of the shapes' residuals after the projection away from ``means``
    (J, B), and whether each is significant against its noise and the means' (module doc)."""
    from scipy.stats import chi2

    n, b = shapes.shape
    j = len(means)
    coeff = shapes @ np.linalg.pinv(means) if j else np.zeros((n, 0))
    residual = shapes - coeff @ means
    variance = sigma**2 + coeff**2 @ mean_sigma**2
    chi = np.sum(residual**2 / variance, axis=1)
    return np.einsum("nb,nb->n", residual, residual), chi2.sf(chi, b - j) < PUREST_DISTINCT_P / n


def _vertices(
    shapes: F64, sigma: F64, k: int, local: tuple[F64, F64]
) -> tuple[NDArray[np.intp], F64, F64, list[NDArray[np.intp]], int]:
    """Noise-weighted successive projections (module doc, step 3) on the local means
    ``local`` (mean, std): the rows picked, the cluster means (K, B) of the shapes around
    them and their standard deviations, the members of each, and how many vertices the
    shapes themselves show significant."""
    b = shapes.shape[1]
    means = np.zeros((0, b))
    mean_sigma = np.zeros((0, b))
    picked, members = [], []
    distinct = k
    for j in range(k):
        _, significant = _significant_residual(shapes, sigma, means, mean_sigma)
        if not np.any(significant):
            distinct = min(distinct, j)
        score, local_significant = _significant_residual(*local, means, mean_sigma)
        if not np.any(local_significant):
            local_significant[:] = True
        score = np.where(local_significant, score, -np.inf)
        i = int(np.argmax(score))
        mean, std, member = _cluster(shapes, sigma, i)
        means = np.vstack([means, mean])
        mean_sigma = np.vstack([mean_sigma, std])
        picked.append(i)
        members.append(member)
    return np.asarray(picked, dtype=np.intp), means, mean_sigma, members, distinct


def _notes(
    support: list[int], distinct: int, k: int, means: F64, mean_sigma: F64
) -> tuple[str, ...]:
    out = []
    if distinct < k:
        out.append(
            f"only {distinct} of the {k} endmembers differ from the others above the noise "
            f"(from endmember {distinct + 1} on, every epoch is a mixture of the first "
            f"{distinct} within its noise): two materials may have nearly the same spectral "
            f"shape, or the data hold fewer materials than asked; ask for at most {distinct}"
        )
    for a in range(k):
        for c in range(a + 1, k):
            d2 = np.mean((means[a] - means[c]) ** 2 / (mean_sigma[a] ** 2 + mean_sigma[c] ** 2))
            if d2 < PUREST_CLUSTER_CHI2:
                out.append(
                    f"endmembers {a + 1} and {c + 1} have the same spectral shape within the "
                    "noise: the data cannot tell them apart"
                )
    out += [
        f"endmember {j + 1} rests on {n} epoch(s) only: it may be a mixture (fewer pure "
        "epochs than endmembers asked)"
        for j, n in enumerate(support)
        if n < PUREST_MIN_EPOCHS
    ]
    return tuple(out)
