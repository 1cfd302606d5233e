"""``unmix_per_epoch``: each epoch unmixed with its own signatures.

References: a noise-free mixture with known contributions (x_n = a_n S_n exactly, so NNLS
and FCLS recover a_n to rounding where a_n is feasible), and :func:`speclight.estimate.unmix`
applied to one epoch at a time (tested against closed forms in test_estimate_unmix.py), which
the vectorised solver must reproduce for noisy data, every method, to rounding.
"""

from __future__ import annotations

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.estimate import UNMIX_METHODS, unmix, unmix_per_epoch

ROUNDING = 1e-10
RNG = np.random.default_rng(12)
N, K, B = 60, 3, 6
S = RNG.uniform(0.05, 1.0, size=(N, K, B))


def test_known_contributions_come_back() -> None:
    a = RNG.uniform(0.02, 0.5, size=(N, K))
    x = np.einsum("nk,nkb->nb", a, S)
    got = unmix_per_epoch(x, S, "nnls")
    np.testing.assert_allclose(got.abundance, a, atol=ROUNDING)
    assert np.all(got.residual < ROUNDING)
    norm = unmix_per_epoch(x, S, "nnls-norm").abundance
    np.testing.assert_allclose(norm, a / a.sum(axis=1, keepdims=True), atol=ROUNDING)


@pytest.mark.parametrize("method", UNMIX_METHODS)
def test_matches_unmix_one_epoch_at_a_time(method: str) -> None:
    a = RNG.uniform(-0.1, 0.6, size=(N, K))
    x = np.einsum("nk,nkb->nb", a, S) + RNG.normal(0.0, 0.05, size=(N, B))
    x[5] = np.nan  # an unlit epoch: NaN row
    s = S.copy()
    s[9, 0, 0] = np.nan  # an epoch without light has no signatures: NaN row
    got = unmix_per_epoch(x, s, method)  # type: ignore[arg-type]
    for n in range(N):
        if n in (5, 9):
            assert np.all(np.isnan(got.abundance[n])) and np.isnan(got.residual[n])
            continue
        one = unmix(x[n : n + 1], s[n], method)  # type: ignore[arg-type]
        np.testing.assert_allclose(got.abundance[n], one.abundance[0], atol=ROUNDING)
        np.testing.assert_allclose(got.residual[n], one.residual[0], atol=ROUNDING)


def test_shapes_are_checked() -> None:
    with pytest.raises(InputError, match="N = 4 epochs"):
        unmix_per_epoch(np.ones((4, B)), S, "nnls")
    with pytest.raises(InputError, match="more than the"):
        unmix_per_epoch(np.ones((N, 2)), S[:, :, :2], "nnls")
