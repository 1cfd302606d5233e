"""Refinement of the ``purest`` vertices (:mod:`.endmember_purest`) by the misfit of the
non-negative fits of all shapes.

Successive projections take, at each step, the shape farthest from the span of the ones
chosen. Where a material's shape drifts along the pass by more than two materials differ
(on the simulated four-material cube the solar cell's band shape changes by ~1.6 deg with
the atmosphere's transmission while aluminium and white paint are 1.3 deg apart), that picks
the drift's far end. Each vertex in turn is then replaced by the candidate that makes the
total chi-square of the non-negative least-squares fits of all shapes by the K vertices
smallest, if any does (the exchange of N-FINDR, Winter 1999, doi:10.1117/12.366289, with
the misfit for the volume): a mixture or a drift's end taken for a vertex leaves the pure
epochs of the missed material unexplained. Candidates for vertex ``j`` are the
``PUREST_CANDIDATES`` local means of largest residual and the as many of largest chi-square
after the projection away from the other vertices; sweeps repeat until none changes (at
most ``PUREST_SWEEPS``). The misfit is computed on at most ``PUREST_MISFIT_SAMPLES`` evenly
spaced shapes.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.spectra.endmember_shapes import (
    cluster,
    noise_scale_profile,
    significant_residual,
)

F64 = NDArray[np.float64]
#: Candidates per criterion (residual, chi-square) tried for each vertex.
PUREST_CANDIDATES = 5
#: Most sweeps over the vertices.
PUREST_SWEEPS = 3
#: Most shapes whose fits make the misfit.
PUREST_MISFIT_SAMPLES = 2000
Picks = tuple[list[int], F64, F64, list[NDArray[np.intp]]]


def misfit(shapes: F64, sigma: F64, vertices: F64) -> float:
    """Total chi-square of the shapes' non-negative fits by the (K, B) vertices, with the
    noise as a per-sample scale times one band profile (:func:`.noise_scale_profile`): the
    bands divided by the profile, the rows' squared residuals by their scale squared (a
    row's NNLS solution does not depend on the row's weight). Raises
    ``numpy.linalg.LinAlgError`` for dependent vertices."""
    from speclight.estimate.spectra.unmixing import _enumerated

    scale, profile = noise_scale_profile(sigma)
    xw, sw = shapes / profile, vertices / profile
    r = xw - _enumerated(xw, sw, sum_to_one=False) @ sw
    return float(np.sum(np.einsum("nb,nb->n", r, r) / scale**2))


def refine(shapes: F64, sigma: F64, local: tuple[F64, F64], picks: Picks) -> Picks:
    """The picks (rows, means (K, B), their standard deviations, members) after the
    exchanges of the module doc; ``local`` the local means and their standard deviations."""
    picked, means, mean_sigma, members = list(picks[0]), picks[1], picks[2], list(picks[3])
    n = len(shapes)
    sub = np.unique(np.linspace(0, n - 1, min(n, PUREST_MISFIT_SAMPLES)).astype(np.intp))

    def total(vertices: F64) -> float:
        try:
            return misfit(shapes[sub], sigma[sub], vertices)
        except np.linalg.LinAlgError:
            return np.inf

    best = total(means)
    for _ in range(PUREST_SWEEPS):
        changed = False
        for j in range(len(picked)):
            for c in _candidates(local, np.delete(means, j, 0), np.delete(mean_sigma, j, 0)):
                if c == picked[j]:
                    continue
                mean, std, member = cluster(shapes, sigma, c)
                trial = means.copy()
                trial[j] = mean
                value = total(trial)
                if value < best:
                    best, means = value, trial
                    mean_sigma = mean_sigma.copy()
                    mean_sigma[j] = std
                    picked[j], members[j] = c, member
                    changed = True
        if not changed:
            break
    return picked, means, mean_sigma, members


def _candidates(local: tuple[F64, F64], means: F64, mean_sigma: F64) -> list[int]:
    """Rows of the local means of largest residual and of largest chi-square after the
    projection away from ``means``, among the significant ones (all if none is)."""
    score, significant, chi = significant_residual(*local, means, mean_sigma)
    if not np.any(significant):
        significant[:] = True
    score = np.where(significant, score, -np.inf)
    chi = np.where(significant, chi, -np.inf)
    top = np.concatenate(
        [np.argsort(-score)[:PUREST_CANDIDATES], np.argsort(-chi)[:PUREST_CANDIDATES]]
    )
    return [int(c) for c in np.unique(top) if np.isfinite(score[c])]
