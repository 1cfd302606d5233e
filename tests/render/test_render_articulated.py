"""Rendering articulated parts: Sun-tracking plates against Lambert's law, shadows by the bus."""

import numpy as np
import pytest

from speclight.render.articulated import pose_groups, render_articulated
from speclight.render.session import RenderSession
from speclight.target import Material, Part, Reflectance, Target, plate
from speclight.target.articulation import Joint

WL = np.array([500.0, 600.0])
RHO = 0.6
WHITE = Material("white", "lambertian", Reflectance.constant(RHO))
BLACK = Material("black", "lambertian", Reflectance.constant(0.0))


def _vertical_array(w: float = 2.0, h: float = 2.0) -> Part:
    """A w x h plate in the x-z plane (normal +y): it must turn 90 deg about x to face +z."""
    p = plate(w, h, WHITE).parts[0]
    v = p.vertices_m[:, [0, 2, 1]] * np.array([1.0, 1.0, 1.0])  # (x, y, 0) -> (x, 0, y)
    return Part("array", v, p.faces, WHITE)


def _render(target, joint, sun, obs, res_px, caster_variant, step=0.0):
    session = RenderSession.create("single", caster_variant, target.materials)
    angles = joint.angles_rad(sun, np.zeros(len(sun), "datetime64[ns]"))[:, None]
    return render_articulated(
        target,
        (joint,),
        angles,
        sun,
        obs,
        np.ones((len(sun), 2)),
        WL,
        session=session,
        angle_step_deg=step,
        resolution_px=res_px,
    )


def test_sun_tracking_plate_follows_lambert(caster_variant):
    # A plate tracking the Sun about x (Sun directions in the y-z plane, the hinge
    # perpendicular to them) faces the Sun: cos(theta_i) = 1, and Lambert's law gives
    # I = (rho / pi) E A |n . o| with n = s (closed form). Pixel-centre sampling errs by at most
    # the perimeter x pitch over the projected area (as in test_render_single_closed_forms).
    target = Target((_vertical_array(),))
    joint = Joint("array", (1.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), "sun_tracking")
    el = np.radians([10.0, 35.0, 60.0, 90.0, 125.0])
    sun = np.c_[np.zeros(5), np.cos(el), np.sin(el)]
    obs = np.array([[0.3, 0.5, 0.8]] * 5)
    obs /= np.linalg.norm(obs, axis=1, keepdims=True)
    res = _render(target, joint, sun, obs, 96, caster_variant)
    cos_o = np.abs(np.einsum("nk,nk->n", sun, obs))
    ref = RHO / np.pi * 4.0 * cos_o
    pitch = 2 * np.sqrt(2.0) / 96
    bound = 8.0 * pitch / (4.0 * cos_o)
    got = res.intensity_W_sr_nm[:, 0]
    assert np.all(np.abs(got - ref) <= bound * ref)
    # without the articulation the vertical plate would give (rho/pi) A cos_i cos_o: the
    # test can tell (the largest difference is well above the bound)
    fixed = RHO / np.pi * 4.0 * np.abs(sun[:, 1]) * np.abs(obs[:, 1])
    assert np.max(np.abs(fixed - ref) / ref) > 3 * bound.max()


def test_bus_between_sun_and_array_shadows_half_of_it(caster_variant):
    # The array (2 m x 2 m, built vertical) turns to face the Sun at zenith and lies in the
    # plane z = 0, x in [-1, 1]. A black 1 m x 2 m "bus" panel 1 m above it covers x in
    # [-1, 0]: its shadow is exactly half the array. The observer, 60 deg off zenith toward +x,
    # sees the array under the bus's edge: a ray from the array at x >= -1 crosses z = 1 at
    # x >= -1 + tan(60 deg) > 0, clear of the bus. So I = (rho / pi) E (A / 2) cos(60 deg).
    array = _vertical_array()
    bus_plate = plate(1.0, 2.0, BLACK).parts[0]
    bus = Part("bus", bus_plate.vertices_m + np.array([-0.5, 0.0, 1.0]), bus_plate.faces, BLACK)
    joint = Joint("array", (1.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), "sun_tracking")
    sun = np.array([[0.0, 0.0, 1.0]])
    obs = np.array([[np.sin(np.pi / 3), 0.0, np.cos(np.pi / 3)]])
    res_px = 256
    shadowed = _render(Target((array, bus)), joint, sun, obs, res_px, caster_variant)
    ref = RHO / np.pi * 2.0 * 0.5
    radius = Target((array, bus)).bounding_sphere()[1]
    pitch = 2 * radius / res_px
    # outlines: the array (8 m) and the shadow edge (2 m), over the array's projected area
    bound = 10.0 * pitch / (4.0 * 0.5)
    assert bound < 0.25  # an unshadowed array (twice the reference) would fail
    assert shadowed.intensity_W_sr_nm[0, 0] == pytest.approx(ref, rel=bound)


def test_pose_groups_round_angles_to_the_step():
    a = np.radians([[0.1], [0.4], [0.8], [359.9], [180.0]])
    poses, group = pose_groups(a, 0.5)
    np.testing.assert_allclose(np.degrees(poses[group, 0]), [0.0, 0.5, 1.0, 0.0, 180.0], atol=1e-9)
    exact, g0 = pose_groups(a, 0.0)
    assert len(exact) == 5 and len(set(g0.tolist())) == 5
