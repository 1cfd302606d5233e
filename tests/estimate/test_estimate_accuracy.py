"""Confusion matrix, errors, spectral angle, reference units (speclight.estimate.spectra.accuracy).

References: hand-worked cases (the numbers are derived in the comments), and the spectral
angle's definition (Kruse et al. 1993, doi:10.1016/0034-4257(93)90013-N).
"""

from __future__ import annotations

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.estimate import (
    confusion_matrix,
    fractions,
    in_reference_units,
    mean_absolute_share_error,
    spectral_angle_rad,
    true_contributions,
)
from speclight.estimate.spectra.accuracy import match_by_angle, merge_columns
from speclight.estimate.spectra.ground_truth import matched_angles_deg

ROUNDING = 1e-12

# Five epochs, two classes. True dominant classes 0, 0, 1, 1, 0; estimated 0, 1, 1, 1, 0.
TRUE = np.array([[0.9, 0.1], [0.8, 0.2], [0.3, 0.7], [0.4, 0.6], [0.6, 0.4]])
EST = np.array([[0.7, 0.3], [0.4, 0.6], [0.2, 0.8], [0.45, 0.55], [0.55, 0.45]])


def test_confusion_matrix_hand_worked() -> None:
    # class 0 dominates epochs 0, 1, 4: estimated 0, 1, 0 -> row [2/3, 1/3];
    # class 1 dominates epochs 2, 3: estimated 1, 1 -> row [0, 1]
    expected = np.array([[2 / 3, 1 / 3], [0.0, 1.0]])
    np.testing.assert_allclose(confusion_matrix(TRUE, EST), expected, atol=ROUNDING)


def test_mean_absolute_share_error_hand_worked() -> None:
    # |differences| per epoch: 0.2, 0.4, 0.1, 0.05, 0.05, each twice -> 1.6 / 10
    assert mean_absolute_share_error(TRUE, EST) == pytest.approx(0.16, abs=ROUNDING)


def test_nan_epochs_are_left_out_and_empty_classes_are_nan_rows() -> None:
    true = np.vstack([np.hstack([TRUE, np.zeros((5, 1))]), [[np.nan, 0.5, 0.5]]])
    est = np.vstack([np.hstack([EST, np.zeros((5, 1))]), [[1.0, 0.0, 0.0]]])
    cm = confusion_matrix(true, est)
    np.testing.assert_allclose(cm[:2, :2], [[2 / 3, 1 / 3], [0.0, 1.0]], atol=ROUNDING)
    assert np.all(np.isnan(cm[2]))  # no epoch is dominated by class 2
    assert mean_absolute_share_error(true, est) == pytest.approx(1.6 / 15, abs=ROUNDING)


def test_confusion_counts_the_dominant_endmember() -> None:
    # true dominant 0, 1, 0 (and a NaN epoch, left out); estimated 0, 0, 0
    truth = np.array([[0.9, 0.1], [0.2, 0.8], [0.6, 0.4], [np.nan, 1.0]])
    est = np.array([[0.7, 0.3], [0.6, 0.4], [0.9, 0.1], [0.5, 0.5]])
    np.testing.assert_array_equal(confusion_matrix(truth, est, normalise=False), [[2, 0], [1, 0]])


def test_fractions_of_per_material_contributions() -> None:
    # epoch 0: material parts (0.3, 0.1) and (0.2, 0.4) on unit signatures (1, 0), (0, 1):
    # contributions 0.3 and 0.4 -> fractions 3/7, 4/7; epoch 1 is dark (all 0) and epoch 2
    # has a NaN: both NaN rows
    c = np.array(
        [
            [[0.3, 0.1], [0.2, 0.4]],
            [[0.0, 0.0], [0.0, 0.0]],
            [[np.nan, 0.1], [0.2, 0.4]],
        ]
    )
    g = true_contributions(c, ["a", "b"], ["a", "b"], np.eye(2))
    f = fractions(g)
    np.testing.assert_allclose(f[0], [3 / 7, 4 / 7], atol=ROUNDING)
    assert np.all(np.isnan(f[1:]))


def test_abundance_in_reference_units() -> None:
    # a = (2, 1), S rows (0.1, 0.1) and (0.5, 0.3), references (1, 1): projections
    # 0.2 / 2 = 0.1 and 0.8 / 2 = 0.4 -> (0.2, 0.4) -> fractions 1/3, 2/3; scaling a (as
    # nnls-norm does) leaves the fractions unchanged
    s = np.array([[0.1, 0.1], [0.5, 0.3]])
    ref = np.ones((2, 2))
    np.testing.assert_allclose(
        in_reference_units([[2.0, 1.0]], s, ref), [[0.2, 0.4]], atol=ROUNDING
    )
    scaled = fractions(in_reference_units([[2 / 3, 1 / 3]], s, ref))
    np.testing.assert_allclose(scaled, [[1 / 3, 2 / 3]], atol=ROUNDING)


def test_merge_columns_sums_into_classes() -> None:
    merged = merge_columns([[0.1, 0.2, 0.7]], [1, 0, 1], 2)
    np.testing.assert_allclose(merged, [[0.2, 0.8]], atol=ROUNDING)
    with pytest.raises(InputError, match="classes"):
        merge_columns([[0.1, 0.9]], [0, 2], 2)


def test_spectral_angle_and_matching() -> None:
    # (1, 0) and (1, 1): 45 deg; proportional signatures: 0
    angle = spectral_angle_rad([[1.0, 0.0], [2.0, 2.0]], [[1.0, 1.0], [3.0, 0.0]])
    np.testing.assert_allclose(np.degrees(angle), [[45.0, 0.0], [0.0, 45.0]], atol=1e-12)
    np.testing.assert_array_equal(
        match_by_angle([[1.0, 0.1], [0.2, 1.0]], [[0, 1], [1, 0]]), [1, 0]
    )


def test_hungarian_matching_leaves_a_dark_signature_out() -> None:
    true = np.array([[1.0, 0.0], [0.0, 1.0]])
    found = np.array([[0.0, 0.0], [0.0, 3.0], [2.0, 0.1]])  # a dark row pairs with nothing
    angle, partner = matched_angles_deg(true, found)
    np.testing.assert_allclose(angle, [np.degrees(np.arctan(0.05)), 0.0], atol=1e-12)
    np.testing.assert_array_equal(partner, [2, 1])
    assert np.isnan(spectral_angle_rad(found[:1], true)).all()


def test_shapes_are_checked() -> None:
    with pytest.raises(InputError, match=r"\(N, C\)"):
        confusion_matrix(np.zeros((3, 2)), np.zeros((3, 3)))
    with pytest.raises(InputError, match="references"):
        in_reference_units(np.zeros((3, 2)), np.zeros((2, 4)), np.zeros((2, 3)))
