"""Spin about another body axis (``spin_body_axis``) against its geometric definition.

References: the definition of the spin model (docs/scenario.md: the body axis b points along
the RA/Dec spin axis at every epoch, the body turns right-handed by 360 deg per period) and
the default, which must reproduce the spin about body z bit for bit.
"""

from __future__ import annotations

import numpy as np
import pytest

from speclight.attitude import quat_to_matrix, spin_attitude, unit_vector_from_radec
from speclight.errors import InputError
from speclight.scenario import parse_scenario
from speclight.scenario.builtin_examples import example_text
from speclight.simulation.geometry_stage import attitude_quaternions

#: Round-off on O(1) direction cosines.
ROUNDOFF = 1e-13


def test_default_axis_is_the_z_spin() -> None:
    t = np.linspace(0.0, 500.0, 101)
    ref = spin_attitude(t, 30.0, 45.0, 120.0, 10.0)
    for axis in ([0, 0, 1], [0, 0, 2.5]):
        got = spin_attitude(t, 30.0, 45.0, 120.0, 10.0, axis)
        np.testing.assert_allclose(got, ref, rtol=0, atol=ROUNDOFF)
    loaded = parse_scenario(example_text("box-wing"), source="box-wing")
    cfg = loaded.scenario.attitude
    assert list(cfg.spin_body_axis) == [0.0, 0.0, 1.0]  # type: ignore[union-attr]
    np.testing.assert_allclose(
        attitude_quaternions(cfg, t), spin_attitude(t, 30.0, 45.0, 120.0, 0.0), atol=ROUNDOFF
    )


@pytest.mark.parametrize("b", [[0, 1, 0], [1, 0, 0], [0, 0, -1], [1, -2, 0.5]])
def test_body_axis_stays_on_the_inertial_axis_and_turns_once_per_period(b) -> None:
    period, ra, dec = 50.0, 200.0, -35.0
    t = np.linspace(0.0, 2 * period, 41)
    r = quat_to_matrix(spin_attitude(t, ra, dec, period, 15.0, b))
    unit_b = np.asarray(b, float) / np.linalg.norm(b)
    axis = unit_vector_from_radec(ra, dec)
    np.testing.assert_allclose(r @ unit_b, np.broadcast_to(axis, (t.size, 3)), atol=ROUNDOFF)
    # a body vector perpendicular to b turns about the axis by 360 deg * t / period
    w = np.cross(unit_b, [0.3, 0.5, 0.7])
    w /= np.linalg.norm(w)
    v = r @ w
    ang = np.arctan2(np.cross(v[0], v) @ axis, v @ v[0])
    expected = 2 * np.pi * t / period
    np.testing.assert_allclose(np.angle(np.exp(1j * (ang - expected))), 0.0, atol=1e-12)


@pytest.mark.parametrize("b", [[0, 0, 0], [np.nan, 0, 1], [1, 0]])
def test_bad_body_axis_is_refused(b) -> None:
    with pytest.raises(InputError, match="spin_body_axis"):
        spin_attitude(np.arange(3.0), 0.0, 0.0, 10.0, 0.0, b)


def test_scenario_refuses_a_zero_body_axis() -> None:
    text = example_text("box-wing").replace(
        "initial_phase_deg: 0.0", "initial_phase_deg: 0.0\n  spin_body_axis: [0, 0, 0]"
    )
    with pytest.raises(InputError, match="spin_body_axis"):
        parse_scenario(text, source="x")
