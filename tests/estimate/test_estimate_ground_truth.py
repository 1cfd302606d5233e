"""Small helpers of speclight.estimate.ground_truth on hand-worked cases."""

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.estimate.ground_truth import (
    dominant_confusion,
    fractions,
    matched_angles_deg,
    material_signatures,
    spectral_angle_deg,
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


def test_confusion_counts_the_dominant_endmember():
    truth = np.array([[0.9, 0.1], [0.2, 0.8], [0.6, 0.4], [np.nan, 1.0]])
    est = np.array([[0.7, 0.3], [0.6, 0.4], [0.9, 0.1], [0.5, 0.5]])
    np.testing.assert_array_equal(dominant_confusion(truth, est), [[2, 0], [1, 0]])


def test_spectral_angles_and_matching():
    assert spectral_angle_deg([1.0, 0.0], [1.0, 1.0])[0] == pytest.approx(45.0)
    true = np.array([[1.0, 0.0], [0.0, 1.0]])
    found = np.array([[0.0, 0.0], [0.0, 3.0], [2.0, 0.1]])  # a dark row pairs with nothing
    angle, partner = matched_angles_deg(true, found)
    np.testing.assert_allclose(angle, [np.degrees(np.arctan(0.05)), 0.0], atol=1e-12)
    np.testing.assert_array_equal(partner, [2, 1])
