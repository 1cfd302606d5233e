"""Uniform spin and fixed attitude against their geometric definitions.

References: the spin model's definition (body z on the spin axis; body x at phase 0
on the ascending node z_gcrs × axis; right-handed rotation by 360 deg per period), the
standard right-hand rule, and finite differencing of the quaternion kinematics
dq/dt = ½ q ⊗ (0, ω_body) (Markley & Crassidis 2014, ch. 3).
"""

from __future__ import annotations

import numpy as np
import pytest

from speclight.attitude import (
    fixed_attitude,
    quat_conjugate,
    quat_multiply,
    quat_to_matrix,
    spin_attitude,
    unit_vector_from_radec,
)
from speclight.errors import InputError

#: Round-off on O(1) direction cosines.
ROUNDOFF = 1e-13
#: Phase error allowed after many turns [rad]: t/period is reduced to one turn before
#: scaling by 2 pi, so only ~1e-16 relative error in t/period remains (1e4 turns here).
PHASE_TOL_RAD = 1e-10


def _angle_about(axis: np.ndarray, ref: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Right-handed angle of v from ref about axis [rad] in (-pi, pi]."""
    return np.arctan2(
        np.einsum("ni,ni->n", np.cross(ref, v), np.broadcast_to(axis, v.shape)),
        np.einsum("ni,ni->n", np.broadcast_to(ref, v.shape), v),
    )


@pytest.mark.parametrize(("ra", "dec"), [(30.0, 45.0), (200.0, -10.0), (0.0, 0.0)])
def test_spin_axis_and_phase(ra: float, dec: float) -> None:
    period = 12.0
    phase0 = 25.0
    t = np.linspace(0.0, 3.0 * period, 97)
    r = quat_to_matrix(spin_attitude(t, ra, dec, period, initial_phase_deg=phase0))
    axis = unit_vector_from_radec(ra, dec)
    # body z stays on the spin axis
    np.testing.assert_allclose(r[:, :, 2], np.broadcast_to(axis, (t.size, 3)), atol=ROUNDOFF)
    # x axis at phase 0 is the ascending node of the spin plane on the equator
    node = np.cross([0.0, 0.0, 1.0], axis)
    node /= np.linalg.norm(node)
    expected = np.radians(phase0 + 360.0 * t / period)
    got = _angle_about(axis, node, r[:, :, 0])
    np.testing.assert_allclose(np.angle(np.exp(1j * (got - expected))), 0.0, atol=1e-12)


def test_spin_advances_one_turn_per_period_after_many_turns() -> None:
    period = 7.3
    t = np.array([0.0, 1e4 * period, 1e4 * period + period / 4.0])
    r = quat_to_matrix(spin_attitude(t, 123.0, 33.0, period))
    np.testing.assert_allclose(r[1], r[0], atol=PHASE_TOL_RAD)
    # a quarter period later x has moved to where y was (right-handed about z)
    np.testing.assert_allclose(r[2][:, 0], r[0][:, 1], atol=PHASE_TOL_RAD)


def test_spin_angular_velocity_is_along_body_z() -> None:
    # ω_body from the kinematics, 2 (q* ⊗ dq/dt), by central differences: (0, 0, 2 pi / P).
    period, h = 10.0, 1e-4
    t = np.array([3.0 - h, 3.0 + h, 3.0])
    q = spin_attitude(t, 75.0, -40.0, period)
    dq = (q[1] - q[0]) / (2 * h)
    omega = 2.0 * quat_multiply(quat_conjugate(q[2]), dq)
    # truncation error of the central difference ~ (omega h)^2 / 6 * omega
    np.testing.assert_allclose(omega, [0.0, 0.0, 0.0, 2 * np.pi / period], atol=1e-7)


@pytest.mark.parametrize("dec", [90.0, -90.0])
def test_spin_about_pole_uses_gcrs_x(dec: float) -> None:
    r = quat_to_matrix(spin_attitude(np.array([0.0]), 10.0, dec, 5.0))[0]
    np.testing.assert_allclose(r[:, 0], [1.0, 0.0, 0.0], atol=ROUNDOFF)
    np.testing.assert_allclose(r[:, 2], [0.0, 0.0, np.sign(dec)], atol=ROUNDOFF)
    assert np.linalg.det(r) == pytest.approx(1.0, abs=ROUNDOFF)


@pytest.mark.parametrize("period", [0.0, -5.0, np.inf, np.nan])
def test_spin_rejects_bad_period(period: float) -> None:
    with pytest.raises(InputError, match="period_s") as info:
        spin_attitude(np.arange(3.0), 0.0, 0.0, period)
    assert info.value.field == "attitude.period_s"


def test_spin_rejects_bad_declination() -> None:
    with pytest.raises(InputError, match="spin_axis_dec_deg"):
        spin_attitude(np.arange(3.0), 0.0, 95.0, 10.0)


def test_fixed_from_quaternion_and_from_radec() -> None:
    q = np.array([np.cos(0.3), 0.0, np.sin(0.3), 0.0])
    out = fixed_attitude(4, q)
    assert out.shape == (4, 4)
    np.testing.assert_allclose(out, np.tile(q, (4, 1)))
    # z toward RA 90 Dec 0 (GCRS y), x toward the celestial pole (GCRS z)
    r = quat_to_matrix(
        fixed_attitude(2, z_ra_deg=90.0, z_dec_deg=0.0, x_ra_deg=0.0, x_dec_deg=90.0)
    )
    # columns are the body axes in GCRS: x -> (0, 0, 1), y = z × x -> (1, 0, 0), z -> (0, 1, 0)
    expected = np.column_stack(([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]))
    np.testing.assert_allclose(r[0], expected, atol=ROUNDOFF)
    np.testing.assert_allclose(r[1], expected, atol=ROUNDOFF)
    np.testing.assert_allclose(fixed_attitude(3), np.tile([1.0, 0, 0, 0], (3, 1)))


def test_fixed_rejects_bad_inputs() -> None:
    with pytest.raises(InputError, match="norm"):
        fixed_attitude(3, [1.0, 1.0, 0.0, 0.0])
    with pytest.raises(InputError, match="not both"):
        fixed_attitude(3, [1.0, 0.0, 0.0, 0.0], z_ra_deg=0.0)
    with pytest.raises(InputError, match="missing"):
        fixed_attitude(3, z_ra_deg=0.0, z_dec_deg=10.0)
    with pytest.raises(InputError, match="parallel"):
        fixed_attitude(3, z_ra_deg=5.0, z_dec_deg=10.0, x_ra_deg=5.0, x_dec_deg=10.0)
