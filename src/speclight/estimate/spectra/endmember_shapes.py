"""Noise-aware helpers of the ``purest`` extraction (:mod:`.endmember_purest`) on the
shapes of samples (each sample divided by its band sum) and their standard deviations."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]
#: A sample belongs to a chosen shape when its mean squared normalised distance is below this.
PUREST_CLUSTER_CHI2 = 2.0
#: Most samples among which each sample's neighbours within its noise are sought (the cost
#: grows as samples x neighbours x bands).
PUREST_NEIGHBOURS = 2000
#: Pairs in one block of the neighbour search (8 MB per temporary array).
PUREST_CHUNK = 1_000_000
#: Probability that noise alone makes any of the samples' residuals significant (divided by
#: the number of samples for each one: Bonferroni).
PUREST_DISTINCT_P = 1e-3


def noise_scale_profile(sigma: F64) -> tuple[F64, F64]:
    """``sigma_ib ~ c_i p_b``: the rows' root mean square ``c`` (N,) and the median band
    profile ``p`` (B,) of the (N, B) standard deviations."""
    scale = np.sqrt(np.mean(sigma**2, axis=1))
    return scale, np.sqrt(np.median((sigma / scale[:, None]) ** 2, axis=0))


def local_means(shapes: F64, sigma: F64) -> tuple[F64, F64]:
    """Each shape's inverse-variance mean with the shapes within its noise (N, B), and its
    standard deviation (N, B).

    The neighbours are sought among at most ``PUREST_NEIGHBOURS`` evenly spaced samples, with
    the noise written as a per-sample scale times one band profile, ``sigma_ib = c_i p_b``
    (``c_i`` the sample's root mean square noise, ``p_b`` the median profile), so that the
    distances of all pairs are one matrix product; the means use every band's own noise.
    """
    n, b = shapes.shape
    ref = np.unique(np.linspace(0, n - 1, min(n, PUREST_NEIGHBOURS)).astype(np.intp))
    scale, profile = noise_scale_profile(sigma)
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


def cluster(shapes: F64, sigma: F64, i: int) -> tuple[F64, F64, NDArray[np.intp]]:
    """Inverse-variance mean (B,) of the shapes within the noise of shape ``i``, its
    standard deviation (B,) and the members."""
    d2 = np.mean((shapes - shapes[i]) ** 2 / (sigma**2 + sigma[i] ** 2), axis=1)
    member = np.flatnonzero(d2 < PUREST_CLUSTER_CHI2)
    w = 1.0 / sigma[member] ** 2
    return (shapes[member] * w).sum(axis=0) / w.sum(axis=0), 1.0 / np.sqrt(w.sum(axis=0)), member


def significant_residual(
    shapes: F64, sigma: F64, means: F64, mean_sigma: F64
) -> tuple[F64, NDArray[np.bool_], F64]:
    """Squared norm (N,) of the shapes' residuals after the projection away from ``means``
    (J, B), whether each is significant against its noise and the means' (module doc), and
    its chi-square (N,)."""
    from scipy.stats import chi2

    n, b = shapes.shape
    j = len(means)
    coeff = shapes @ np.linalg.pinv(means) if j else np.zeros((n, 0))
    residual = shapes - coeff @ means
    variance = sigma**2 + coeff**2 @ mean_sigma**2
    chi = np.sum(residual**2 / variance, axis=1)
    significant = chi2.sf(chi, b - j) < PUREST_DISTINCT_P / n
    return np.einsum("nb,nb->n", residual, residual), significant, chi
