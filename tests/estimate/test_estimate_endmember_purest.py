"""``purest`` extraction with noise (issue 25 item 5): the purest epochs, not bright or
noisy ones, and a note where the data cannot separate the endmembers asked.

Reference: synthetic mixtures ``x = a S + w`` drawn here from known signatures ``S`` with
Gaussian noise of known sigma (fixed seeds); the angles are to those true signatures. The
set mimics the shipped materials: two bright grey signatures 1.3 deg apart (aluminium and
white paint are 1.32 deg apart through the cube-materials bands) and two dark coloured ones,
whose faint pure epochs have noisy shapes (a shape's noise is the noise over the band sum).
"""

from __future__ import annotations

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.estimate.spectra.accuracy import spectral_angle_rad
from speclight.estimate.spectra.endmembers import extract_endmembers
from speclight.estimate.spectra.ground_truth import matched_angles_deg
from speclight.estimate.spectra.unmix_run import _check_independent

B = 10
WL = np.linspace(0.0, 1.0, B)
S = np.array(
    [
        np.full(B, 0.9),
        0.8 + 0.06 * (WL - 0.5),
        0.05 + 0.3 * np.exp(-(((WL - 0.2) / 0.15) ** 2)),
        0.1 + 0.25 * WL**2,
    ]
)


def _mixtures(snr: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """10 faint pure epochs per material among 300 bright mixtures; ``snr`` is that of a
    pure epoch's mean band."""
    rng = np.random.default_rng(seed)
    pure = np.repeat(np.eye(len(S)), 10, axis=0) * 0.2
    mixed = rng.dirichlet(np.full(len(S), 2.0), size=300) * rng.uniform(0.5, 1.0, (300, 1))
    x = np.vstack([pure, mixed]) @ S
    sigma = np.full(x.shape, 0.2 * float(S.mean()) / snr)
    return x + rng.normal(0.0, sigma), sigma


def test_close_grey_signatures_are_told_apart_above_the_noise() -> None:
    angle = np.degrees(spectral_angle_rad(S[:1], S[1:2]))[0, 0]
    assert 1.0 < angle < 1.6  # the case: two greys about as close as aluminium and paint
    x, sigma = _mixtures(snr=200.0, seed=1)
    found = extract_endmembers(x, 4, "purest", sigma)
    angles, _ = matched_angles_deg(S, found.signatures)
    # one pure epoch's shape is ~1/SNR rad = 0.3 deg off at this SNR, the averages less;
    # a swap of the two greys would put both 1.3 deg off, any other mix-up > 10 deg
    assert np.max(angles) < 1.0
    assert found.notes == ()


def test_greys_within_the_noise_are_said_to_be_inseparable() -> None:
    x, sigma = _mixtures(snr=15.0, seed=2)  # one epoch's shape ~4 deg off: greys merge
    found = extract_endmembers(x, 4, "purest", sigma)
    assert any(
        "differ from the others" in note or "same spectral shape" in note for note in found.notes
    )


def test_more_endmembers_than_materials_are_said_so() -> None:
    x, sigma = _mixtures(snr=200.0, seed=3)
    found = extract_endmembers(x, 6, "purest", sigma)
    assert any(note.startswith("only 4 of the 6 endmembers") for note in found.notes)


def test_dependent_extracted_signatures_are_refused_naming_n() -> None:
    twice = np.vstack([S[:2], S[:1]])
    with pytest.raises(InputError, match=r"ask for n <= 2") as err:
        _check_independent(twice, ("only 2 of the 3 endmembers differ",))
    assert err.value.field == "n"


@pytest.mark.parametrize("seed", [0, 2])
def test_a_drifting_shape_does_not_take_the_place_of_a_material(seed: int) -> None:
    """The dark material's shape drifts by 1 deg over its pure epochs (as the atmosphere
    moves a solar cell's band shape along a pass), as much as the two greys differ: the
    drift's far end must not be taken as a fourth material (without the exchange of
    :mod:`.endmember_refine` both seeds fail: 7 of 12 seeds tried did)."""
    rng = np.random.default_rng(seed)
    pattern = np.sin(6 * WL)
    pattern = (pattern - pattern.mean()) / pattern.std()
    dark = S[2] * (1.0 + 0.015 * np.linspace(-1.0, 1.0, 20)[:, None] * pattern)
    span = np.degrees(spectral_angle_rad(dark[:1], dark[-1:]))[0, 0]
    assert 0.8 < span < 1.2
    pure = np.vstack([np.repeat(0.2 * S[[0, 1, 3]], 10, axis=0), 0.6 * dark])
    mixed = rng.dirichlet(np.full(len(S), 2.0), size=300) * rng.uniform(0.5, 1.0, (300, 1))
    x = np.vstack([pure, mixed @ S])
    sigma = np.full(x.shape, 0.2 * float(S.mean()) / 150.0)
    x = x + rng.normal(0.0, sigma)
    angles, _ = matched_angles_deg(S, extract_endmembers(x, 4, "purest", sigma).signatures)
    # the dark material's reference is its mid-drift shape, the ends 0.5 deg from it
    assert np.max(angles) < 1.0
