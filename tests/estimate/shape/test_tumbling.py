"""Tumbling: a torque-free box-wing rendered by speclight over two passes, its state fitted
through speclight's torque-free propagation (issue 27, "Tumbling")."""

from __future__ import annotations

import os

import numpy as np
import pytest
import xarray as xr
from scipy.spatial.transform import Rotation

from conftest import WHITE, render_mesh
from speclight.attitude import torque_free_attitude
from speclight.attitude.quaternion import quat_conjugate, quat_rotate
from speclight.estimate.shape import tumbling
from speclight.estimate.shape.convex_model import facet_brightness
from speclight.estimate.shape.egi import mesh_facets
from speclight.estimate.shape.inversion_data import build_inversion_data
from speclight.estimate.shape.scattering import scattering_law
from speclight.estimate.shape.tumbling import (
    FAMILY_ANGLE_DEG,
    FAMILY_RELATIVE,
    TumblingState,
    fit_tumbling,
    same_family,
)
from speclight.estimate.shape.tumbling_light import ConvexLight, MapLight, tabulated_map
from speclight.estimate.shape.tumbling_mirror import mirror_plane, mirror_state
from speclight.estimate.shape.tumbling_run import add_tumbling
from speclight.target import shapes

MOMENTS = np.array([0.45, 0.8, 1.0])  # principal moments / the largest
W0 = np.array([0.01, 0.03, 0.02])  # body rates at the first epoch [rad/s] (~3 min a turn)
Q0 = np.array([0.9, 0.1, -0.3, 0.2]) / np.linalg.norm([0.9, 0.1, -0.3, 0.2])


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _two_passes():
    """Two 10-min passes 90 min apart, a point every 10 s; the Sun fixed, the observer
    sweeping 60 deg across the sky in each pass (directions from the target, ecliptic)."""
    t_s = np.concatenate([np.arange(0, 600, 10.0), 5400 + np.arange(0, 600, 10.0)])
    sun = np.tile(_unit(np.array([1.0, 0.2, 0.1])), (t_s.size, 1))
    az = np.deg2rad(np.concatenate([np.linspace(60, 120, 60), np.linspace(50, 110, 60)]))
    obs = _unit(np.stack([np.cos(az), np.sin(az), 0.3 * np.ones_like(az)], axis=1))
    return t_s, sun, obs


def _convex_case(moments, w0, seed, name, every=1):
    """Convex-model light curves (Lambert, 1 % noise from ``seed``) of the dishless box-wing
    turning torque-free from ``Q0`` with ``moments`` and body rates ``w0`` over
    :func:`_two_passes` (every ``every``-th point): the data, the convex light model, the
    epochs [s]."""
    tgt = shapes.box_wing(WHITE, dish=False)
    normals, areas = mesh_facets([(p.vertices_m, p.faces) for p in tgt.parts])
    t_s, sun, obs = (a[::every] for a in _two_passes())
    q, _ = torque_free_attitude(t_s, moments, Q0, w0)
    qc = quat_conjugate(q)
    law = scattering_law("lambert")
    chp = np.sqrt(0.5 * (1 + np.sum(sun * obs, axis=1)))
    y = facet_brightness(quat_rotate(qc, sun), quat_rotate(qc, obs), normals, areas, law, chp)
    rng = np.random.default_rng(seed)
    sigma = 0.01 * np.mean(y)
    t_jd = 2459000.5 + t_s / 86400.0
    half = t_s.size // 2
    data = build_inversion_data(
        t_jd, y + sigma * rng.normal(size=y.size), np.full(y.size, sigma), sun, obs,
        np.repeat([0, 1], half), np.array([False, False]), name,
    )  # fmt: skip
    return data, ConvexLight(normals, areas, law), t_s


#: The far-start searches and the full principal-axis check run the grid search (1.5-2
#: CPU minutes each, ~9 wall minutes on busy cores for the null case, ~4 with the
#: reflectivity map: its 221,184 node renders and lookups): too long for the suite's
#: 12-minute budget. They run where SPECLIGHT_LONG_TESTS=1 is set (a fast null test runs always);
#: bench/bench_tumbling_far.py measures the search over random draws.
LONG = pytest.mark.skipif(
    not os.environ.get("SPECLIGHT_LONG_TESTS"),
    reason="the tumbling grid search takes minutes: set SPECLIGHT_LONG_TESTS=1",
)


def _angle_deg(a, b):
    return np.degrees(np.arccos(np.clip(a @ b, -1.0, 1.0)))


def _far_start():
    """A start far from the truth: the attitude turned by 120 deg, the rates 60 deg off and
    30 % slower, moments (0.3, 0.9, 1): the fit's grid and continuation must find the way."""
    off = Rotation.from_rotvec(np.deg2rad(120.0) * _unit(np.array([1.0, -1.0, 0.5])))
    w_off = Rotation.from_rotvec(np.deg2rad(60.0) * _unit(np.array([0.0, 1.0, 1.0]))).apply(W0)
    return TumblingState(
        (Rotation.from_quat(Q0, scalar_first=True) * off).as_quat(scalar_first=True),
        0.7 * w_off,
        np.array([0.3, 0.9, 1.0]),
        0.0,
    )


def _rendered_case():
    """The torque-free box-wing rendered by speclight over the two passes (1 % noise): the
    data, its parts, and its vertices and faces as one mesh."""
    tgt = shapes.box_wing(WHITE, dish=False)
    parts = [(p.vertices_m, p.faces) for p in tgt.parts]
    t_s, sun, obs = _two_passes()
    q, _ = torque_free_attitude(t_s, MOMENTS, Q0, W0)
    qc = quat_conjugate(q)
    vertices = np.vstack([v for v, _ in parts])
    faces = np.vstack([f + sum(len(v) for v, _ in parts[:k]) for k, (_, f) in enumerate(parts)])
    # speclight's render: the bus and wings with their shadows on each other
    y = render_mesh(vertices, faces, quat_rotate(qc, sun), quat_rotate(qc, obs))
    rng = np.random.default_rng(0)
    sigma = 0.01 * np.mean(y)
    t_jd = 2459000.5 + t_s / 86400.0
    data = build_inversion_data(
        t_jd, y + sigma * rng.normal(size=y.size), np.full(y.size, sigma), sun, obs,
        np.repeat([0, 1], 60), np.array([False, False]), "tf",
    )  # fmt: skip
    return data, parts, vertices, faces


@pytest.fixture(scope="module")
def rendered_far_fit():
    """The torque-free box-wing rendered by speclight (shadows included), fitted with no
    prior but a far start; the truth's own best fit; the truth and its mirror state."""
    data, parts, _, _ = _rendered_case()
    truth = TumblingState(Q0, W0, MOMENTS, 0.0)
    far = _far_start()
    assert not same_family(far, truth)
    sun, obs = data.sun_ecliptic, data.observer_ecliptic
    normals, areas = mesh_facets(parts)
    law = scattering_law("lambert")
    common = dict(min_period_h=0.03, max_period_h=0.1, n_starts=0, t0_jd=data.time_jd[0])
    convex = ConvexLight(normals, areas, law)
    fit = fit_tumbling(data, convex, initial_states=[far], rate_span=0.015, **common)
    at_truth = fit_tumbling(
        data, convex, initial_states=[truth], rate_span=0.0, grid=False, **common
    )
    mirror = mirror_state(truth, mirror_plane(sun, obs)[0])
    return fit, at_truth, truth, mirror


@LONG
def test_far_start_reaches_the_truths_momentum_and_rate(rendered_far_fit):
    """From the far start the search ends at least as low as the truth's own best fit
    (chi-square; the convex model lacks the shadows, so that is not the truth's state), and
    a reported family has the truth's momentum direction (or its mirror's: the passes' Sun
    and observer directions lie within 0.6 deg rms of one plane, tumbling_mirror.py) within
    the families' 10 deg and the rate within their 5 %; it beats a principal-axis rotation."""
    fit, at_truth, truth, mirror = rendered_far_fit
    assert fit.families[0][0].chi2 <= at_truth.families[0][0].chi2
    assert any(
        _angle_deg(f[0].momentum_direction, ref.momentum_direction) <= FAMILY_ANGLE_DEG
        and abs(f[0].rate_rad_s / ref.rate_rad_s - 1.0) <= FAMILY_RELATIVE
        for f in fit.families
        for ref in (truth, mirror)
    )
    assert fit.detected  # better than any rotation about a principal axis (F-test)


@LONG
def test_far_start_recovers_the_state_when_the_model_is_right():
    """The same case and far start with light curves from the convex model itself (the
    fitted model, no shadows; 1 % noise): the truth's family is reported and tumbling is
    detected. Where the model is right the search reaches the state; on the rendered
    light curves the model error moves the best fit (the xfail below)."""
    data, light, _ = _convex_case(MOMENTS, W0, 0, "tf")
    fit = fit_tumbling(
        data, light, min_period_h=0.03, max_period_h=0.1, n_starts=0,
        initial_states=[_far_start()], t0_jd=data.time_jd[0], rate_span=0.015,
    )  # fmt: skip
    assert any(same_family(f[0], TumblingState(Q0, W0, MOMENTS, 0.0)) for f in fit.families)
    assert fit.detected


@LONG
@pytest.mark.xfail(
    strict=True,
    reason="issue 27 item 3 open: the convex model lacks the shadows of the rendered "
    "box-wing, and its best fit (chi2 3803 against 7497 for the truth's own) has the "
    "smaller moment ratio 0.53 where the truth has 0.45 (3.9 sigma); BENCHMARKS.md. With "
    "the reflectivity map as the light model it is recovered (the test below)",
)
def test_torque_free_box_wing_state_recovered(rendered_far_fit):
    fit, _, truth, mirror = rendered_far_fit
    assert any(same_family(f[0], truth) or same_family(f[0], mirror) for f in fit.families)


@LONG
def test_far_start_with_the_reflectivity_map_recovers_the_state():
    """The rendered case and far start with the box-wing's reflectivity map as the light
    model (tumbling_light.py; rendered by speclight at the map's nodes: HEALPix nside 8,
    phase angles 30-110 deg every 10 deg, 32 rolls, 64 px; so with the shadows the convex
    model lacks): the truth's (or its mirror's) family is reported, moment ratios
    included, and tumbling is detected. The map's own error (interpolation, 64 px against
    the data's 128 px) is a chi-square of about 750 on the 120 points, the convex model's
    about 7,500 (BENCHMARKS.md)."""
    data, _, vertices, faces = _rendered_case()
    rmap = tabulated_map(
        lambda s, o: render_mesh(vertices, faces, s, o, resolution_px=64),
        nside=8,
        phase_angle_deg=np.arange(30.0, 120.0, 10.0),
        n_rolls=32,
    )
    fit = fit_tumbling(
        data, MapLight(rmap), min_period_h=0.03, max_period_h=0.1, n_starts=0,
        initial_states=[_far_start()], t0_jd=data.time_jd[0], rate_span=0.015,
    )  # fmt: skip
    truth = TumblingState(Q0, W0, MOMENTS, 0.0)
    mirror = mirror_state(truth, mirror_plane(data.sun_ecliptic, data.observer_ecliptic)[0])
    assert any(same_family(f[0], truth) or same_family(f[0], mirror) for f in fit.families)
    assert fit.detected


@LONG
def test_principal_axis_rotation_is_not_tumbling():
    """A box-wing spinning about its axis of largest moment (no nutation): the torque-free
    fit must not claim a tumbling state (F-test against a principal-axis rotation)."""
    w0 = np.array([0.0, 0.0, 0.035])  # about body z, the largest moment of MOMENTS
    data, light, _ = _convex_case(MOMENTS[[1, 0, 2]], w0, 1, "pa")
    fit = fit_tumbling(
        data, light, min_period_h=0.03, max_period_h=0.1, n_starts=0,
        t0_jd=data.time_jd[0], rate_span=0.015,
    )  # fmt: skip
    assert not fit.detected


def test_principal_axis_rotation_is_not_tumbling_fast():
    """The null case in seconds: a convex-model light curve of a box-wing spinning about its
    axis of largest moment, fitted from a tumbling start near it (rates 20 deg off the axis,
    other moments) without the grid. The torque-free fit's 4 extra parameters fit the noise
    a little better (chi-square lower by about chi2(4)); the F-test against the best
    principal-axis rotation must not call that tumbling (p >= 0.001)."""
    w0 = np.array([0.0, 0.0, 0.035])  # about body z, the largest moment
    data, light, t_s = _convex_case(MOMENTS[[1, 0, 2]], w0, 2, "pa", every=2)  # every 20 s
    tilt = Rotation.from_rotvec(np.deg2rad(20.0) * np.array([1.0, 0.0, 0.0]))
    start = TumblingState(Q0, tilt.apply(w0), np.array([0.6, 0.9, 1.0]), 0.0)
    fit = fit_tumbling(
        data, light, min_period_h=0.03, max_period_h=0.1, n_starts=0,
        initial_states=[start], t0_jd=data.time_jd[0], rate_span=0.0, grid=False,
    )  # fmt: skip
    assert not fit.detected
    ds = add_tumbling(xr.Dataset(), fit)  # SHAPE.nc's variables, the std ones finite
    assert ds.attrs["tumbling_detected"] == 0
    assert np.all(np.isfinite(ds.tumbling_rate_std)) and np.all(ds.tumbling_rate_std > 0)
    assert np.all(np.isfinite(ds.tumbling_moment_ratio_std))
    assert ds.tumbling_momentum_direction_std.dims == ("family", "east_north")
    # the searched periods: the given lower end; the upper one the longer pass's span (from
    # the epochs in JD: float64 resolves 4e-5 s there, 1e-7 of the 580 s span)
    span_h = max(np.ptp(t_s[:30]), np.ptp(t_s[30:])) / 3600.0
    assert ds.attrs["tumbling_searched_period_h"][0] == pytest.approx(0.03)
    assert ds.attrs["tumbling_searched_period_h"][1] == pytest.approx(max(0.1, span_h), rel=1e-6)


def test_body_symmetry_keeps_the_family():
    """A box-wing without its dish is symmetric under a half turn about its x axis: the
    states q0 and q0 R_x(180 deg) (rates turned with it) give the same light curve and are
    one family."""
    tgt = shapes.box_wing(WHITE, dish=False)
    normals, areas = mesh_facets([(p.vertices_m, p.faces) for p in tgt.parts])
    half = Rotation.from_rotvec([np.pi, 0, 0])
    other = TumblingState(
        (Rotation.from_quat(Q0, scalar_first=True) * half).as_quat(scalar_first=True),
        half.inv().apply(W0),
        MOMENTS,
        0.0,
    )
    truth = TumblingState(Q0, W0, MOMENTS, 0.0)
    assert same_family(truth, other)
    t_s, sun, obs = _two_passes()
    law = scattering_law("lambert")
    chp = np.sqrt(0.5 * (1 + np.sum(sun * obs, axis=1)))
    from speclight.estimate.shape.convex_model import facet_brightness

    curves = []
    for s in (truth, other):
        q, _ = torque_free_attitude(t_s, s.moments, s.q0, s.omega0_body_rad_s)
        qc = quat_conjugate(q)
        curves.append(
            facet_brightness(quat_rotate(qc, sun), quat_rotate(qc, obs), normals, areas, law, chp)
        )
    assert np.allclose(curves[0], curves[1], rtol=1e-9, atol=1e-12 * np.max(curves[0]))


def test_mirror_state_gives_the_same_light_curve_in_a_plane():
    """The mirror ambiguity (tumbling_mirror.py): with every Sun and observer direction in
    one plane, the state reflected through it (attitude -M R, the same body rates and
    moments) shows the centrally symmetric box-wing's facets to antipodal directions, which
    a Lambert law lights alike: the same light curve to round-off, and the momentum -M H
    (an axial vector under a reflection)."""
    tgt = shapes.box_wing(WHITE, dish=False)
    normals, areas = mesh_facets([(p.vertices_m, p.faces) for p in tgt.parts])
    t_s, sun, obs = _two_passes()
    tilt = Rotation.from_rotvec([0.3, -0.2, 0.1])  # the plane: not a coordinate plane
    sun, obs = tilt.apply(sun * [1, 1, 0]), tilt.apply(obs * [1, 1, 0])
    sun, obs = _unit(sun), _unit(obs)
    normal, rms_sine = mirror_plane(sun, obs)
    assert rms_sine < 1e-12
    assert abs(abs(normal @ tilt.apply([0.0, 0.0, 1.0])) - 1.0) < 1e-12
    truth = TumblingState(Q0, W0, MOMENTS, 0.0)
    mirror = mirror_state(truth, normal)
    reflect = np.eye(3) - 2 * np.outer(normal, normal)
    assert np.allclose(mirror.momentum_direction, -reflect @ truth.momentum_direction, atol=1e-12)
    law = scattering_law("lambert")
    chp = np.sqrt(0.5 * (1 + np.sum(sun * obs, axis=1)))
    curves = []
    for s in (truth, mirror):
        q, _ = torque_free_attitude(t_s, s.moments, s.q0, s.omega0_body_rad_s)
        qc = quat_conjugate(q)
        curves.append(
            facet_brightness(quat_rotate(qc, sun), quat_rotate(qc, obs), normals, areas, law, chp)
        )
    assert np.allclose(curves[0], curves[1], rtol=1e-9, atol=1e-12 * np.max(curves[0]))
    assert not same_family(truth, mirror)  # a different state, not a body symmetry


def test_draws_around_a_short_fit_find_the_cycle_count_over_the_gap():
    """The hop (``tumbling._hopped``, :func:`.tumbling_search.local_draws`): a fit to the
    first 15 points (150 s, 0.75 of a turn) from a start one turn off over the 90-min gap
    leaves the rate 4 % off; least squares on both passes from there ends in another
    cycle count (chi-square over 100 times the truth's minimum), while draws around the
    short fit from its own covariance, scored on both passes, and the best refined reach
    the truth's minimum (the refit from the truth, to 0.1 %), for each of 3 draw seeds
    (8 of 8 when tried).
    Convex model, no model error: the state is identifiable."""
    data, light, _ = _convex_case(MOMENTS, W0, 2, "hop")
    truth = TumblingState(Q0, W0, MOMENTS, 0.0)
    t0 = float(data.time_jd[0])
    both = tumbling._Problem(data, light, t0)
    short = tumbling._Problem(data.subset(np.arange(15)), light, t0)
    at_truth = tumbling._fit_all(both, [tumbling._state_vector(truth, 1.0)])[0].chi2
    turns_over_gap = 5400.0 * truth.rate_rad_s / (2 * np.pi)
    start = tumbling._state_vector(truth, 1.0 + 1.0 / turns_over_gap)
    short_fit = tumbling._fit_all(short, [start])[0]
    assert abs(short_fit.rate_rad_s / truth.rate_rad_s - 1.0) > 0.02
    direct = tumbling._fit_all(both, [tumbling._state_vector(short_fit, 1.0)])[0]
    assert direct.chi2 > 100 * at_truth
    for r in range(3):
        hopped = tumbling._hopped(short, both, [short_fit], np.random.default_rng(r))
        assert hopped[0].chi2 == pytest.approx(at_truth, rel=1e-3)
        assert same_family(hopped[0], truth)
