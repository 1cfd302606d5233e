"""Small helpers of speclight.estimate.spectra.ground_truth on hand-worked cases (the confusion
matrix and spectral-angle cases are in test_estimate_accuracy.py)."""

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.estimate.spectra.ground_truth import (
    fractions,
    material_signatures,
    true_contributions,
)


def test_signatures_of_a_grey_and_a_step_spectrum():
    wl = np.array([400.0, 500.0, 600.0, 700.0])
    band = np.array([[1.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 1.0]])
    rho = np.array([[0.5, 0.5, 0.5, 0.5], [0.0, 1.0, 1.0, 1.0]])
    s = material_signatures(rho, band, wl)
    # photon weights ~ lambda (equal bin widths): band 1 = (0 * 400 + 1 * 500) / 900
    np.testing.assert_allclose(s, [[0.5, 0.5], [500.0 / 900.0, 1.0]], rtol=1e-12)
    # a source that is dark at 400 nm moves band 1 of the step to 1
    s = material_signatures(rho, band, wl, source_W_m2_nm=[0.0, 1.0, 1.0, 1.0])
    np.testing.assert_allclose(s[1], [1.0, 1.0], rtol=1e-12)


def test_true_contributions_sum_the_materials_of_one_label():
    sig = np.array([[1.0, 0.0], [0.0, 2.0]])
    shares = np.array([[[0.3, 0.0], [0.1, 0.0], [0.0, 0.8]]])  # two faces of "a", one of "b"
    g = true_contributions(shares, ["a", "a", "b"], ["a", "b"], sig)
    np.testing.assert_allclose(g, [[0.4, 0.4]])
    np.testing.assert_allclose(fractions(g), [[0.5, 0.5]])
    with pytest.raises(InputError, match="have no endmember"):
        true_contributions(shares, ["a", "a", "c"], ["a", "b"], sig)


def test_per_epoch_sources_give_per_epoch_signatures():
    # the step spectrum of the test above under a flat source, then one dark at 400 nm, then
    # no light at all (NaN): the rows of the single-source results
    wl = np.array([400.0, 500.0, 600.0, 700.0])
    band = np.array([[1.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 1.0]])
    rho = np.array([[0.0, 1.0, 1.0, 1.0]])
    source = np.array([[1.0, 1.0, 1.0, 1.0], [0.0, 1.0, 1.0, 1.0], [0.0, 0.0, 0.0, 0.0]])
    s = material_signatures(rho, band, wl, source_W_m2_nm=source)
    assert s.shape == (3, 1, 2)
    np.testing.assert_allclose(s[0, 0], [500.0 / 900.0, 1.0], rtol=1e-12)
    np.testing.assert_allclose(s[1, 0], [1.0, 1.0], rtol=1e-12)
    assert np.all(np.isnan(s[2]))
    # per-epoch contributions: F = g s(t) projected back on s(t)
    g = true_contributions(2.0 * s[:2], ["a"], ["a"], s[:2])
    np.testing.assert_allclose(g, [[2.0], [2.0]], rtol=1e-12)
