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
   bench: 32 % -> 100 % of draws within 3 deg);
4. each vertex in turn is exchanged for the candidate that makes the misfit of the
   non-negative fits of all shapes smallest (:mod:`.endmember_refine`), which corrects a
   pick at the far end of a material whose shape drifts along the pass.

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

from speclight.estimate.spectra.endmember_refine import refine
from speclight.estimate.spectra.endmember_shapes import (
    PUREST_CLUSTER_CHI2,
    cluster,
    local_means,
    significant_residual,
)

F64 = NDArray[np.float64]
#: Least signal-to-noise ratio ``|x| / |sigma|`` of a sample whose shape is used (the
#: significance test of step 3 weighs the noise of the rest; 5 kept the pure epochs of a dark
#: material that 10 dropped, on the bench).
PUREST_MIN_SNR = 5.0
#: Without noise estimates: least norm, as a fraction of the 90th percentile of the norms.
PUREST_MIN_BRIGHTNESS = 0.1
#: Fewest epochs a signature should rest on before it is called supported.
PUREST_MIN_EPOCHS = 3


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
    local = local_means(shapes[rows], shape_sigma)
    picked, means, mean_sigma, members, distinct = _vertices(shapes[rows], shape_sigma, k, local)
    scale = np.array([np.median(total[rows][m]) for m in members])
    notes = _notes([m.size for m in members], distinct, k, means, mean_sigma)
    return (
        rows[picked],
        means * scale[:, None],
        notes,
    )


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
        _, significant, _ = significant_residual(shapes, sigma, means, mean_sigma)
        if not np.any(significant):
            distinct = min(distinct, j)
        score, local_significant, _ = significant_residual(*local, means, mean_sigma)
        if not np.any(local_significant):
            local_significant[:] = True
        score = np.where(local_significant, score, -np.inf)
        i = int(np.argmax(score))
        mean, std, member = cluster(shapes, sigma, i)
        means = np.vstack([means, mean])
        mean_sigma = np.vstack([mean_sigma, std])
        picked.append(i)
        members.append(member)
    picked, means, mean_sigma, members = refine(
        shapes, sigma, local, (picked, means, mean_sigma, members)
    )
    return np.asarray(picked, dtype=np.intp), means, mean_sigma, members, distinct


def _notes(
    support: list[int], distinct: int, k: int, means: F64, mean_sigma: F64
) -> tuple[str, ...]:
    out = []
    if distinct < k:
        out.append(
            f"only {distinct} of the {k} endmembers differ from the others above the noise "
            f"(every epoch is a mixture of {distinct} of them within its noise): two "
            "materials may have nearly the same spectral shape, or the data hold fewer "
            f"materials than asked; ask for at most {distinct}"
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
