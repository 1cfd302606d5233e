"""Body-frame directions of the Sun, the observer and the phase vector."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from speclight.attitude.quaternion import FloatArray, quat_to_matrix

#: |sun + observer| below this (unit vectors, so sin of half the angle from opposite):
#: the bisector is undefined and the phase vector is NaN.
OPPOSITE_LIMIT = 1e-12


def to_body(q: ArrayLike, v_gcrs: ArrayLike) -> FloatArray:
    """Express GCRS vectors in the body frame: ``v_body = R(q)^T @ v_gcrs``.

    Parameters
    ----------
    q
        Body-to-GCRS quaternions, shape (N, 4) (or (4,), broadcast).
    v_gcrs
        Vectors in GCRS, shape (N, 3) (or (3,), broadcast); any unit.

    Returns
    -------
    numpy.ndarray
        The same vectors in body components, shape (N, 3). NaN rows stay NaN.
    """
    return np.einsum("...ji,...j->...i", quat_to_matrix(q), np.asarray(v_gcrs, dtype=np.float64))


def _unit(v: FloatArray) -> FloatArray:
    norm = np.linalg.norm(v, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(norm > 0.0, v / norm, np.nan)


def body_directions(
    q: ArrayLike, sun_dir_gcrs: ArrayLike, observer_dir_gcrs: ArrayLike
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Sun, observer and phase-vector unit vectors in the body frame.

    Parameters
    ----------
    q
        Body-to-GCRS quaternions, shape (N, 4).
    sun_dir_gcrs
        Target-to-Sun directions in GCRS, shape (N, 3); normalised here, so position
        differences [m] may be passed.
    observer_dir_gcrs
        Target-to-observer directions in GCRS, shape (N, 3); normalised here.

    Returns
    -------
    sun_dir_body, observer_dir_body, phase_vector_body : numpy.ndarray
        Unit vectors (N, 3) in the body frame. The phase vector is the bisector
        ``normalize(sun + observer)`` (Nussbaum et al. 2022, "Spectral light curve
        simulation for parameter estimation from space debris", Fig. 1); it is NaN where the
        Sun and the observer are opposite as seen from the target (phase angle 180
        deg, ``|sun + observer| < 1e-12``), and wherever an input row is NaN or zero.
    """
    sun_body = _unit(to_body(q, _unit(np.asarray(sun_dir_gcrs, dtype=np.float64))))
    obs_body = _unit(to_body(q, _unit(np.asarray(observer_dir_gcrs, dtype=np.float64))))
    bisector = sun_body + obs_body
    norm = np.linalg.norm(bisector, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        phase = np.where(norm >= OPPOSITE_LIMIT, bisector / norm, np.nan)
    return sun_body, obs_body, phase
