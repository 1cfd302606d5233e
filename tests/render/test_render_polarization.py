"""Single-scattering polarisation against closed forms written here (issue 15 item 1).

References: the Fresnel equations in the real-angle form for a dielectric (Hecht, Optics,
5th ed., eqs. 4.42-4.43: r_s = -sin(ti - tt) / sin(ti + tt), r_p = tan(ti - tt) /
tan(ti + tt)) and in the (a, b) form for a conductor (Azzam & Bashara, Ellipsometry and
Polarized Light, 1977, sec. 4.3; Born & Wolf sec. 14.2):
2 a^2 = sqrt((n^2 - k^2 - sin^2)^2 + 4 n^2 k^2) + (n^2 - k^2 - sin^2),
2 b^2 = sqrt(...) - (n^2 - k^2 - sin^2), R_s = ((a - c)^2 + b^2) / ((a + c)^2 + b^2),
R_p = R_s ((a - s t)^2 + b^2) / ((a + s t)^2 + b^2), c = cos, s = sin, t = tan of the angle
of incidence. Neither is the form the code uses (complex Snell's law).
"""

from __future__ import annotations

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.render import render_intensity
from speclight.render.polarization import dolp_aolp, rotate_linear
from speclight.target import Material, Reflectance, plate, refractive_index, sphere

POLE = np.array([[0.0, 0.0, 1.0]])  # celestial north = body +z


def _dielectric_rs_rp(theta: float, n: float) -> tuple[float, float]:
    tt = np.arcsin(np.sin(theta) / n)
    rs = -np.sin(theta - tt) / np.sin(theta + tt)
    rp = np.tan(theta - tt) / np.tan(theta + tt)
    return rs * rs, rp * rp


def _conductor_rs_rp(theta: float, n: float, k: float) -> tuple[float, float]:
    s2 = np.sin(theta) ** 2
    x = n * n - k * k - s2
    root = np.sqrt(x * x + 4 * n * n * k * k)
    a, b = np.sqrt((root + x) / 2), np.sqrt((root - x) / 2)
    c, st = np.cos(theta), np.sin(theta) * np.tan(theta)
    rs = ((a - c) ** 2 + b * b) / ((a + c) ** 2 + b * b)
    rp = rs * ((a - st) ** 2 + b * b) / ((a + st) ** 2 + b * b)
    return rs, rp


def _render(target, sun, obs, wl, **kw):
    r = render_intensity(
        target,
        np.atleast_2d(sun),
        np.atleast_2d(obs),
        np.ones(len(wl)),
        wl,
        resolution_px=kw.pop("resolution_px", 32),
        variant="numpy",
        polarization=True,
        pole_body=np.repeat(POLE, len(np.atleast_2d(sun)), axis=0),
        **kw,
    )
    assert r.stokes_W_sr_nm is not None
    return r.intensity_W_sr_nm, r.stokes_W_sr_nm


def _mirror_geometry(theta: float) -> tuple[np.ndarray, np.ndarray]:
    """Sun and observer at incidence ``theta`` on a plate with normal +z, scattering plane
    x-z: the observer at the mirror direction."""
    return (
        np.array([np.sin(theta), 0.0, np.cos(theta)]),
        np.array([-np.sin(theta), 0.0, np.cos(theta)]),
    )


def test_brewster_angle_of_a_smooth_dielectric_plate_fully_polarises() -> None:
    wl = np.array([550.0])
    n = float(refractive_index("SiO2", wl)[0].real)
    glass = Material("glass", "specular", Reflectance.dielectric("SiO2"))
    theta_b = np.arctan(n)
    i, st = _render(plate(1.0, 1.0, glass), *_mirror_geometry(theta_b), wl)
    rs, rp = _dielectric_rs_rp(theta_b, n)
    assert rp < 1e-20
    dolp, _ = dolp_aolp(i, st[..., 0], st[..., 1])
    assert dolp[0, 0] == pytest.approx(1.0, abs=1e-9)
    # off Brewster: DoLP = (Rs - Rp) / (Rs + Rp)
    for deg in (20.0, 45.0, 70.0):
        i, st = _render(plate(1.0, 1.0, glass), *_mirror_geometry(np.radians(deg)), wl)
        rs, rp = _dielectric_rs_rp(np.radians(deg), n)
        dolp, _ = dolp_aolp(i, st[..., 0], st[..., 1])
        assert dolp[0, 0] == pytest.approx((rs - rp) / (rs + rp), rel=1e-9)


def test_plate_polarised_perpendicular_to_the_plane_of_incidence() -> None:
    # The scattering plane is x-z, which holds the pole (north, body +z) and the line of
    # sight: s-polarisation is east-west on the sky, AoLP = 90 deg, Q < 0, U = 0.
    wl = np.array([550.0])
    glass = Material("glass", "specular", Reflectance.dielectric("SiO2"))
    i, st = _render(plate(1.0, 1.0, glass), *_mirror_geometry(np.radians(40.0)), wl)
    _, aolp = dolp_aolp(i, st[..., 0], st[..., 1])
    assert aolp[0, 0] == pytest.approx(90.0, abs=1e-9)
    assert st[0, 0, 0] < 0 and abs(st[0, 0, 1]) < 1e-12 * i[0, 0]
    assert np.all(st[..., 2] == 0.0)


def test_conductor_sphere_matches_closed_form_fresnel_at_the_half_angle() -> None:
    # every microfacet lit and seen has the half vector as normal: the whole sphere's
    # reflection carries the Fresnel Mueller matrix at the half-phase angle
    wl = np.array([450.0, 550.0, 650.0])
    gold = Material("gold", "ggx", Reflectance.conductor("Au"), roughness=0.25)
    alu = Material("alu", "beckmann", Reflectance.conductor("Al"), roughness=0.3)
    phase = np.radians(100.0)
    sun = np.array([np.cos(phase), 0.0, np.sin(phase)])
    obs = np.array([1.0, 0.0, 0.0])
    theta = phase / 2  # angle of incidence on the microfacet
    for mat, name in ((gold, "Au"), (alu, "Al")):
        i, st = _render(sphere(1.0, mat), sun, obs, wl, resolution_px=48)
        eta = refractive_index(name, wl)
        for j in range(len(wl)):
            rs, rp = _conductor_rs_rp(theta, eta[j].real, eta[j].imag)
            q_over_i = -st[0, j, 0] / i[0, j]  # s is east-west here: Q = -Q_s
            assert q_over_i == pytest.approx((rs - rp) / (rs + rp), rel=1e-9)
            assert abs(st[0, j, 1]) < 1e-12 * i[0, j]
        assert np.all(st[..., 2] == 0.0)  # unpolarised Sun, single scattering: V = 0


def test_intensity_unchanged_by_polarization() -> None:
    wl = np.array([450.0, 650.0])
    gold = Material("gold", "ggx", Reflectance.conductor("Au"), roughness=0.25)
    target = sphere(1.0, gold)
    sun, obs = np.array([[0.3, 0.4, 0.8]]), np.array([[0.9, -0.1, 0.2]])
    i, _ = _render(target, sun, obs, wl)
    plain = render_intensity(target, sun, obs, np.ones(2), wl, resolution_px=32, variant="numpy")
    np.testing.assert_allclose(i, plain.intensity_W_sr_nm, rtol=1e-12)  # float64 rounding
    assert plain.stokes_W_sr_nm is None


def test_lambertian_and_non_fresnel_reflectances_are_unpolarised() -> None:
    wl = np.array([500.0, 600.0])
    grey = Material("grey", "lambertian", Reflectance.constant(0.5))
    shiny = Material("shiny", "ggx", Reflectance.constant(0.8), roughness=0.2)  # no n, k
    for m in (grey, shiny):
        i, st = _render(sphere(1.0, m), [0.2, 0.5, 0.8], [1.0, 0.0, 0.0], wl)
        assert np.all(i > 0)
        assert np.all(st == 0.0)
        dolp, aolp = dolp_aolp(i, st[..., 0], st[..., 1])
        assert np.all(dolp == 0.0) and np.all(np.isnan(aolp))  # no angle without polarisation


def test_plastic_coat_polarises_and_base_does_not() -> None:
    # smooth-coated plastic seen away from the glint: only the unpolarised base is seen;
    # a rough coat adds the coat's Fresnel Q at the half angle (real coat index)
    wl = np.array([550.0])
    n = float(refractive_index("SiO2", wl)[0].real)
    base = Reflectance.constant(0.5)
    smooth = Material("p", "plastic", Reflectance.dielectric("SiO2"), diffuse_reflectance=base)
    i, st = _render(sphere(1.0, smooth), [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], wl)
    assert i[0, 0] > 0 and np.all(st == 0.0)
    rough = Material(
        "r", "plastic", Reflectance.dielectric("SiO2"), roughness=0.3, diffuse_reflectance=base
    )
    i, st = _render(sphere(1.0, rough), [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], wl)
    rs, rp = _dielectric_rs_rp(np.radians(45.0), n)
    ratio = -st[0, 0, 0] / i[0, 0]  # s is east-west: Q < 0
    assert 0 < ratio < (rs - rp) / (rs + rp)  # diluted by the unpolarised base


def test_aolp_rotates_with_the_scattering_plane_on_the_sky() -> None:
    # Observer along body +x: line of sight d = -x, east = z x d = -y, north = d x east = +z.
    # Sun direction (0.5, -c, c): the scattering plane's normal is along (0, 1, 1) =
    # (north - east) / sqrt(2): position angle -45 = 135 deg, so U = -p, Q = 0 (hand-worked).
    wl = np.array([550.0])
    gold = Material("gold", "ggx", Reflectance.conductor("Au"), roughness=0.3)
    c = 0.6
    sun = np.array([0.5, -c, c]) / np.linalg.norm([0.5, -c, c])
    i, st = _render(sphere(1.0, gold), sun, [1.0, 0.0, 0.0], wl)
    dolp, aolp = dolp_aolp(i, st[..., 0], st[..., 1])
    assert aolp[0, 0] == pytest.approx(135.0, abs=1e-9)
    assert abs(st[0, 0, 0]) < 1e-12 * i[0, 0] and st[0, 0, 1] < 0
    assert dolp[0, 0] > 0.01


def test_rotate_linear_hand_case() -> None:
    # Q = 1 along a reference at position angle 30 deg: in the north frame the polarisation
    # is at 30 deg, Q = cos 60 = 0.5, U = sin 60
    q, u = rotate_linear(np.array([1.0]), np.array([0.0]), np.radians(30.0))
    assert q[0] == pytest.approx(0.5) and u[0] == pytest.approx(np.sqrt(3) / 2)
    _, aolp = dolp_aolp(np.array([1.0]), q, u)
    assert aolp[0] == pytest.approx(30.0)


def test_measured_materials_refuse_polarization() -> None:
    table = Material(
        "panel", "measured", Reflectance.constant(1.0), brdf_table="starlink_v1p5_solar_array_532nm"
    )
    with pytest.raises(InputError, match=r"panel.*no polarisation model"):
        _render(plate(1.0, 1.0, table), [0.0, 0.0, 1.0], [0.0, 0.3, 1.0], np.array([550.0]))


def test_polarization_needs_the_pole() -> None:
    grey = Material("grey", "lambertian", Reflectance.constant(0.5))
    with pytest.raises(InputError, match="pole_body"):
        render_intensity(
            sphere(1.0, grey), [0, 0, 1], [1, 0, 0], [1.0], [550.0], variant="numpy",
            polarization=True,
        )  # fmt: skip
