"""Endmember extraction (``speclight.estimate.spectra.endmembers``) against independent references.

* ATGP: a hand-made data set whose projection sequence is worked out on paper, and the
  published algorithm (Ren & Chang 2003, doi:10.1109/TAES.2003.1261119, eq. for the
  orthogonal subspace projector ``P = I - U (U^T U)^-1 U^T``) evaluated literally;
* PCA: points on a line (closed form) and the eigen-decomposition of the sample covariance
  (:func:`numpy.linalg.eigh`, a different route than the singular value decomposition);
* N-FINDR (Winter 1999, doi:10.1117/12.366289): pure pixels among mixtures must be found,
  the volume never decreases, and no triple of a small data set (brute force) has a larger
  simplex volume, computed with an independent principal-component projection.
"""

from __future__ import annotations

from itertools import combinations
from math import factorial

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.estimate.spectra.endmembers import extract_endmembers

#: Round-off allowance for exact cases [m2 sr-1].
EXACT = 1e-12

# Three pure signatures [m2 sr-1] chosen so that ATGP's order can be worked out by hand:
# norms 3, sqrt(5), sqrt(3) -> e1 first; away from e1, e2 -> (0, 2, 0, 0) (norm 2) and
# e3 -> (0, 1, 1, 0) (norm sqrt(2)) -> e2; away from e1 and e2, e3 -> (0, 0, 1, 0).
PURE = np.array([[3.0, 0.0, 0.0, 0.0], [1.0, 2.0, 0.0, 0.0], [1.0, 1.0, 1.0, 0.0]])


@pytest.fixture
def pure_and_mixed() -> tuple[np.ndarray, np.ndarray]:
    """40 strict mixtures of PURE plus the 3 pure samples, shuffled; the pure rows' indices.

    The norm and the norm after a projection are convex, so over a set of mixtures their
    maximum is at a vertex: ATGP and N-FINDR must return the pure rows.
    """
    rng = np.random.default_rng(7)
    mixed = rng.dirichlet(np.ones(3), size=40) @ PURE
    x = np.vstack([mixed, PURE])
    order = rng.permutation(len(x))
    x = x[order]
    where = np.array([int(np.flatnonzero(order == 40 + j)[0]) for j in range(3)])
    return x, where


def test_atgp_picks_the_pure_samples_in_the_hand_worked_order(pure_and_mixed):
    x, where = pure_and_mixed
    res = extract_endmembers(x, 3, "atgp")
    np.testing.assert_array_equal(res.indices, where)  # e1, e2, e3 in that order
    np.testing.assert_array_equal(res.signatures, PURE)
    assert res.volumes is None and res.method == "atgp"


def atgp_reference(x: np.ndarray, k: int) -> list[int]:
    """Ren & Chang's ATGP written literally with the projector I - U (U^T U)^-1 U^T."""
    chosen = [int(np.argmax(np.linalg.norm(x, axis=1)))]
    for _ in range(k - 1):
        u = x[chosen].T  # (B, j)
        p = np.eye(x.shape[1]) - u @ np.linalg.inv(u.T @ u) @ u.T
        chosen.append(int(np.argmax(np.linalg.norm(x @ p.T, axis=1))))
    return chosen


def test_atgp_agrees_with_the_published_projector_form():
    rng = np.random.default_rng(1)
    x = rng.uniform(0.0, 1.0, size=(500, 8))
    res = extract_endmembers(x, 6, "atgp")
    assert res.indices is not None
    assert res.indices.tolist() == atgp_reference(x, 6)


def test_non_finite_rows_are_skipped_and_indices_count_the_input_rows(pure_and_mixed):
    x, where = pure_and_mixed
    bad = np.vstack([np.full((1, 4), np.nan), x])
    bad[5, 1] = np.inf  # row 4 of x, a mixture
    for method in ("atgp", "nfindr"):
        res = extract_endmembers(bad, 3, method)
        assert res.indices is not None
        assert sorted(res.indices.tolist()) == sorted((where + 1).tolist())


def test_pca_of_points_on_a_line_is_the_mean_and_one_standard_deviation_along_it():
    # x = m + t d: mean m + mean(t) d, direction d / |d| (largest entry positive),
    # standard deviation std(t) |d| (population)
    m = np.array([0.2, 0.1, 0.4])
    d = np.array([-1.0, -2.0, 0.0])
    t = np.array([-1.0, 0.0, 1.0, 2.5])
    x = m + t[:, None] * d
    res = extract_endmembers(x, 2, "pca")
    assert res.indices is None
    mean = m + t.mean() * d
    np.testing.assert_allclose(res.signatures[0], mean, atol=EXACT)
    np.testing.assert_allclose(res.signatures[1], mean - t.std() * d, atol=EXACT)


def test_pca_agrees_with_the_covariance_eigenvectors_and_lies_in_the_signatures_span():
    rng = np.random.default_rng(4)
    pure = rng.uniform(0.05, 0.9, size=(4, 10))
    x = rng.dirichlet(np.ones(4), size=300) @ pure
    res = extract_endmembers(x, 4, "pca")
    values, vectors = np.linalg.eigh(np.cov(x.T, bias=True))  # ascending
    mean = x.mean(axis=0)
    for i in range(3):
        v = vectors[:, -1 - i]
        v = v if v[np.argmax(np.abs(v))] > 0 else -v
        np.testing.assert_allclose(res.signatures[1 + i], mean + np.sqrt(values[-1 - i]) * v)
    # the paper's observation: linear combinations of the true signatures
    coef, *_ = np.linalg.lstsq(pure.T, res.signatures.T, rcond=None)
    np.testing.assert_allclose(pure.T @ coef, res.signatures.T, atol=1e-10)


def simplex_volume(y: np.ndarray) -> float:
    """Volume of the simplex with vertices the rows of y (K, K-1): |det(edges)| / (K-1)!."""
    edges = y[1:] - y[0]
    return abs(float(np.linalg.det(edges))) / factorial(len(y) - 1)


def pc_scores(x: np.ndarray, n: int) -> np.ndarray:
    """Scores on the n leading eigenvectors of the sample covariance (an independent PCA)."""
    _, vectors = np.linalg.eigh(np.cov(x.T, bias=True))
    return (x - x.mean(axis=0)) @ vectors[:, ::-1][:, :n]


def test_nfindr_finds_the_pure_samples(pure_and_mixed):
    x, where = pure_and_mixed
    res = extract_endmembers(x, 3, "nfindr")
    assert res.indices is not None and res.volumes is not None
    assert sorted(res.indices.tolist()) == sorted(where.tolist())
    np.testing.assert_array_equal(res.signatures, x[res.indices])
    y = pc_scores(x, 2)
    best = max(simplex_volume(y[list(c)]) for c in combinations(range(len(x)), 3))
    np.testing.assert_allclose(res.volumes[-1], best, rtol=1e-10)


def test_nfindr_volume_never_decreases_and_ends_at_a_maximum():
    # no simplex structure (points in a ball): the ATGP start is not the answer, so N-FINDR
    # has to swap; its volumes must grow and end where no single swap helps (a local
    # maximum: Winter's algorithm does not promise the global one)
    rng = np.random.default_rng(11)
    x = rng.normal(size=(25, 4))
    x /= np.maximum(1.0, np.linalg.norm(x, axis=1))[:, None]
    x += 2.0
    res = extract_endmembers(x, 4, "nfindr")
    assert res.indices is not None and res.volumes is not None
    assert len(res.volumes) >= 3, "the case must exercise several swaps"
    assert np.all(np.diff(res.volumes) > 0.0)
    y = pc_scores(x, 3)
    start = extract_endmembers(x, 4, "atgp").indices
    assert start is not None
    np.testing.assert_allclose(res.volumes[0], simplex_volume(y[start]), rtol=1e-10)
    final = simplex_volume(y[res.indices])
    np.testing.assert_allclose(res.volumes[-1], final, rtol=1e-10)
    for j in range(4):  # a local maximum: no replacement of one vertex grows the volume
        for i in range(len(x)):
            trial = res.indices.copy()
            trial[j] = i
            assert simplex_volume(y[trial]) <= final * (1.0 + 1e-10)


def test_k_of_one_is_the_largest_sample_or_the_mean(pure_and_mixed):
    x, where = pure_and_mixed
    res = extract_endmembers(x, 1, "atgp")
    assert res.indices is not None and res.indices.tolist() == [where[0]]
    np.testing.assert_allclose(extract_endmembers(x, 1, "pca").signatures, [x.mean(axis=0)])


@pytest.mark.parametrize(
    ("x", "k", "method", "field", "words"),
    [
        (np.ones(4), 2, "atgp", "x", "x[None, :]"),
        (np.ones((5, 3)), 4, "atgp", "k", "more than the 3 bands"),
        (np.eye(3)[:2], 3, "nfindr", "k", "more than the 2 samples"),
        (np.vstack([np.eye(3)[:2], np.full((1, 3), np.nan)]), 3, "atgp", "k", "2 samples"),
        (np.eye(3), 0, "atgp", "k", ">= 1"),
        (np.eye(3), 1, "nfindr", "k", ">= 2"),
        (np.eye(3), 2.0, "atgp", "k", "integer"),
        (np.eye(3), True, "atgp", "k", "integer"),
        (np.array([[1.0, 0, 0], [2, 0, 0], [3, 0, 0]]), 2, "atgp", "k", "span only 1"),
        (np.eye(3), 2, "ppi", "method", "choices: atgp, pca, nfindr"),
        (np.eye(3), 2, "nfinder", "method", "did you mean 'nfindr'"),
    ],
)
def test_bad_inputs_raise_input_error_naming_the_argument(x, k, method, field, words):
    with pytest.raises(InputError, match=field) as info:
        extract_endmembers(x, k, method)
    assert info.value.field == field
    assert words in str(info.value)
