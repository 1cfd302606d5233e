"""Body-frame Sun, observer and phase vectors against their definitions.

References: v_body = R^T v_gcrs for an orthonormal R (frame change by the transpose);
scipy.spatial.transform.Rotation.apply(..., inverse=True) as an independent
implementation; the phase vector is the bisector of the Sun and observer directions
(Nussbaum et al. 2022, Fig. 1), so it makes half the phase angle with each.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from speclight.attitude import body_directions, spin_attitude, to_body

#: Round-off on O(1) direction cosines.
ROUNDOFF = 1e-13


def _random_setup(n: int = 30) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(21)
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return q, rng.normal(size=(n, 3)) * 1.5e11, rng.normal(size=(n, 3)) * 1e6


def test_to_body_matches_scipy_inverse_rotation() -> None:
    q, sun, _ = _random_setup()
    reference = Rotation.from_quat(np.roll(q, -1, axis=1)).apply(sun, inverse=True)
    np.testing.assert_allclose(to_body(q, sun), reference, rtol=1e-13, atol=1e-3)


def test_body_directions_units_and_bisector() -> None:
    q, sun, obs = _random_setup()
    sun_b, obs_b, phase_b = body_directions(q, sun, obs)
    for v in (sun_b, obs_b, phase_b):
        np.testing.assert_allclose(np.linalg.norm(v, axis=1), 1.0, atol=ROUNDOFF)
    # angles are preserved by the rotation: phase angle in body frame = in GCRS
    cos_gcrs = np.einsum("ni,ni->n", sun, obs) / (
        np.linalg.norm(sun, axis=1) * np.linalg.norm(obs, axis=1)
    )
    np.testing.assert_allclose(np.einsum("ni,ni->n", sun_b, obs_b), cos_gcrs, atol=ROUNDOFF)
    # the phase vector makes half the phase angle with both directions
    half = 0.5 * np.arccos(np.clip(cos_gcrs, -1.0, 1.0))
    np.testing.assert_allclose(np.einsum("ni,ni->n", phase_b, sun_b), np.cos(half), atol=1e-12)
    np.testing.assert_allclose(np.einsum("ni,ni->n", phase_b, obs_b), np.cos(half), atol=1e-12)


def test_sun_direction_turns_backwards_in_a_spinning_body() -> None:
    # A body spinning +90 deg about GCRS z sees a fixed Sun on GCRS x turn by -90 deg.
    q = spin_attitude(np.array([0.0, 1.0]), 0.0, 90.0, 4.0)
    sun_b, _, _ = body_directions(
        q, np.array([[1.0, 0, 0], [1.0, 0, 0]]), np.tile([0, 1.0, 0], (2, 1))
    )
    np.testing.assert_allclose(sun_b, [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0]], atol=ROUNDOFF)


def test_opposite_directions_and_bad_rows_give_nan_phase_vector() -> None:
    q = np.tile([1.0, 0.0, 0.0, 0.0], (3, 1))
    sun = np.array([[1.0, 0.0, 0.0], [np.nan, 0.0, 0.0], [0.0, 0.0, 2.0]])
    obs = np.array([[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 3.0, 0.0]])
    sun_b, obs_b, phase_b = body_directions(q, sun, obs)
    assert np.all(np.isnan(phase_b[:2]))
    assert np.all(np.isnan(sun_b[1])) and np.all(np.isfinite(obs_b[1]))
    np.testing.assert_allclose(phase_b[2], [0.0, np.sqrt(0.5), np.sqrt(0.5)], atol=ROUNDOFF)
