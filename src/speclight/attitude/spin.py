"""Uniform spin about an inertially fixed axis."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from speclight.attitude.quaternion import (
    FloatArray,
    frame_from_axes,
    quat_from_axis_angle,
    quat_multiply,
    unit_vector_from_radec,
)
from speclight.errors import InputError

#: Spin axes with |sin(angle to the celestial pole)| below this use GCRS x as node.
POLE_SIN_LIMIT = 1e-9


def spin_reference_frame(axis_ra_deg: float, axis_dec_deg: float) -> FloatArray:
    """Body-to-GCRS quaternion (4,) of a spinning body at phase 0.

    Body z is the spin axis; body x points along ``normalize(z_gcrs × axis)``, the
    ascending node of the spin plane on the celestial equator, or along GCRS x
    (orthogonalised) when the axis is within 1e-9 rad of a celestial pole.
    """
    axis = unit_vector_from_radec(axis_ra_deg, axis_dec_deg)
    node = np.cross(np.array([0.0, 0.0, 1.0]), axis)
    if np.linalg.norm(node) < POLE_SIN_LIMIT:
        node = np.array([1.0, 0.0, 0.0])
    return frame_from_axes(axis, node, field="attitude.spin_axis_ra_deg/spin_axis_dec_deg")


def body_axis_to_z(spin_body_axis: ArrayLike | None) -> FloatArray | None:
    """Quaternion ``m`` (4,) of the smallest rotation taking ``spin_body_axis`` to body z.

    ``None`` for the default axis (0, 0, 1) (no extra rotation, so the attitudes stay bit
    for bit those of a spin about z). For ``-z`` the rotation is 180 deg about x.

    Raises
    ------
    InputError
        If the axis is not three finite numbers of non-zero length.
    """
    if spin_body_axis is None:
        return None
    b = np.asarray(spin_body_axis, dtype=np.float64)
    norm = float(np.linalg.norm(b)) if b.shape == (3,) else 0.0
    if b.shape != (3,) or not np.all(np.isfinite(b)) or not norm > 0.0:
        raise InputError(
            f"spin_body_axis = {spin_body_axis!r} must be a non-zero body-frame vector [x, y, z]",
            field="attitude.spin_body_axis",
        )
    b = b / norm
    z = np.array([0.0, 0.0, 1.0])
    if np.array_equal(b, z):
        return None
    cross = np.cross(b, z)
    if np.linalg.norm(cross) < POLE_SIN_LIMIT:
        axis = np.array([1.0, 0.0, 0.0]) if b[2] < 0 else z
        angle = np.pi if b[2] < 0 else 0.0
    else:
        axis, angle = cross, float(np.arctan2(np.linalg.norm(cross), b @ z))
    return quat_from_axis_angle(axis, angle)


def spin_attitude(
    t_s: ArrayLike,
    axis_ra_deg: float,
    axis_dec_deg: float,
    period_s: float,
    initial_phase_deg: float = 0.0,
    spin_body_axis: ArrayLike | None = None,
) -> FloatArray:
    """Attitude of a body spinning uniformly about a fixed axis.

    Body z is the spin axis (or ``spin_body_axis``). At phase 0 the body x axis points
    along the ascending node of the spin plane on the celestial equator,
    ``normalize(z_gcrs × axis)`` (GCRS x for an axis at a celestial pole). The body turns
    right-handedly about the axis by ``phase(t) = initial_phase_deg + 360 deg * t_s /
    period_s``; its angular velocity is ``(0, 0, 2 pi / period_s)`` in the body frame.

    With ``spin_body_axis = b`` the body is first turned by ``m``, the smallest rotation
    taking ``b`` to z (:func:`body_axis_to_z`): ``q(t) = q_frame ⊗ q_spin(t) ⊗ m``, so ``b``
    points along the RA/Dec axis at every epoch and the body vector ``m* x m`` (the image of
    body x under the inverse of ``m``) lies on the node at phase 0.

    Parameters
    ----------
    t_s
        Seconds since the scenario start [s], shape (N,). Non-finite times give NaN rows.
    axis_ra_deg, axis_dec_deg
        Spin axis right ascension and declination in GCRS [deg].
    period_s
        Spin period [s], > 0 (reverse the axis for the opposite sense).
    initial_phase_deg
        Phase at ``t_s = 0`` [deg].
    spin_body_axis
        The body-frame axis the body spins about, (3,) (normalised here); ``None`` or
        (0, 0, 1): body z.

    Returns
    -------
    numpy.ndarray
        Body-to-GCRS quaternions, shape (N, 4).

    Raises
    ------
    InputError
        If ``period_s`` is not a finite number > 0 or an angle is not finite.
    """
    if not (np.isfinite(period_s) and period_s > 0.0):
        raise InputError(
            f"period_s = {period_s!r} must be a finite number > 0 [s]; for the opposite "
            "sense of rotation point the spin axis the other way (RA + 180, -Dec)",
            field="attitude.period_s",
        )
    for name, value in (
        ("spin_axis_ra_deg", axis_ra_deg),
        ("spin_axis_dec_deg", axis_dec_deg),
        ("initial_phase_deg", initial_phase_deg),
    ):
        if not np.isfinite(value):
            raise InputError(
                f"{name} = {value!r} must be a finite angle [deg]", field=f"attitude.{name}"
            )
    if not -90.0 <= axis_dec_deg <= 90.0:
        raise InputError(
            f"spin_axis_dec_deg = {axis_dec_deg!r} must be in [-90, 90] [deg]",
            field="attitude.spin_axis_dec_deg",
        )
    t = np.atleast_1d(np.asarray(t_s, dtype=np.float64))
    # Reduce turns before multiplying by 2 pi so that phases stay accurate after many turns.
    turns = np.mod(t / period_s, 1.0)
    phase_rad = np.radians(initial_phase_deg) + 2.0 * np.pi * turns
    half = 0.5 * phase_rad
    q_spin = np.stack((np.cos(half), np.zeros_like(half), np.zeros_like(half), np.sin(half)), -1)
    m = body_axis_to_z(spin_body_axis)
    if m is not None:
        q_spin = quat_multiply(q_spin, m)
    return quat_multiply(spin_reference_frame(axis_ra_deg, axis_dec_deg), q_spin)
