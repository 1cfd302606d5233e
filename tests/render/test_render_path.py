"""Path-traced (multi-bounce Monte Carlo) mode: statistics against closed forms and single mode."""

import numpy as np
import pytest

from speclight.render import available_variants, render_intensity
from speclight.target import Material, Reflectance, box_wing, sphere

pytestmark = pytest.mark.skipif(
    not any(v.endswith("_spectral") and not v.startswith("scalar") for v in available_variants()),
    reason="path mode tests need a vectorised Mitsuba spectral variant",
)
WAVELENGTH_NM = np.arange(400.0, 801.0, 20.0)
#: A z-test at 4 standard errors fails by chance in 6e-5 of runs (normal), more with the
#: 8-pass error estimate (Student t, 7 dof: 5e-3); seeds are fixed, so a pass is reproducible.
Z_MAX = 4.0


def _dirs(phase_deg):
    a = np.radians(np.asarray(phase_deg, dtype=float))
    sun = np.tile([0.0, 0.0, 1.0], (len(a), 1))
    return sun, np.stack([np.sin(a), np.zeros_like(a), np.cos(a)], axis=1)


def test_path_lambertian_sphere_matches_phase_law_within_monte_carlo_error():
    # Lambert sphere I(a) = (2 / (3 pi)) rho E R^2 [sin a + (pi - a) cos a] (Russell 1916).
    # A convex target never lights itself, so path tracing must reproduce the law exactly
    # in expectation (the box pixel filter integrates the pixel area: no discretisation bias).
    rho = 0.6
    phase = np.array([0.0, 60.0, 120.0])
    sun, obs = _dirs(phase)
    e = np.ones((3, len(WAVELENGTH_NM)))
    m = Material("paint", "lambertian", Reflectance.constant(rho))
    res = render_intensity(
        sphere(1.0, m),
        sun,
        obs,
        e,
        WAVELENGTH_NM,
        mode="path",
        resolution_px=64,
        samples_per_pixel=64,
        seed=1,
    )
    a = np.radians(phase)
    ref = 2 / (3 * np.pi) * rho * (np.sin(a) + (np.pi - a) * np.cos(a))
    i, sd = res.intensity_W_sr_nm, res.intensity_std_W_sr_nm
    assert np.all(sd > 0)
    z_mean = (i.mean(axis=1) - ref) / (np.sqrt((sd**2).sum(axis=1)) / len(WAVELENGTH_NM))
    assert np.all(np.abs(z_mean) < Z_MAX)
    # The stated per-bin errors describe the scatter: mean z^2 near 1 (7/5 expected for the
    # 8-pass Student-t estimate; allow up to 3).
    z = (i - ref[:, None]) / sd
    assert 0.3 < np.mean(z**2) < 3.0


def test_path_agrees_with_single_on_a_convex_rough_conductor():
    # Rough aluminium sphere: single scattering is the whole answer for a convex target,
    # so the two modes must agree within the Monte Carlo error (single mode's pixel error
    # on a sphere at 128 px is < 1e-3 relative, added to the tolerance).
    m = Material("al", "beckmann", Reflectance.conductor("Al"), roughness=0.3)
    sun, obs = _dirs([30.0, 100.0])
    e = np.ones((2, len(WAVELENGTH_NM)))
    target = sphere(1.0, m)
    p = render_intensity(
        target,
        sun,
        obs,
        e,
        WAVELENGTH_NM,
        mode="path",
        resolution_px=64,
        samples_per_pixel=64,
        seed=2,
    )
    s = render_intensity(target, sun, obs, e, WAVELENGTH_NM, mode="single", resolution_px=128)
    diff = p.intensity_W_sr_nm.mean(axis=1) - s.intensity_W_sr_nm.mean(axis=1)
    sigma = np.sqrt((p.intensity_std_W_sr_nm**2).sum(axis=1)) / len(WAVELENGTH_NM)
    pixel_error = 1e-3 * s.intensity_W_sr_nm.mean(axis=1)
    assert np.all(np.abs(diff) < Z_MAX * sigma + pixel_error)


def test_path_exceeds_single_on_concave_box_wing():
    # Wings beside the bus form concave corners: light reflected by a wing onto the bus (and
    # back) is seen only with multiple bounces, so path > single by many standard errors.
    white = Material("white", "lambertian", Reflectance.constant(0.9))
    target = box_wing(white)
    # Sun and observer both on the +y side: the +y bus face and the +y wing light each other.
    sun = np.array([[0.2, 1.0, 0.3]]) / np.linalg.norm([0.2, 1.0, 0.3])
    obs = np.array([[0.3, 0.8, 0.2]]) / np.linalg.norm([0.3, 0.8, 0.2])
    e = np.ones((1, len(WAVELENGTH_NM)))
    p = render_intensity(
        target,
        sun,
        obs,
        e,
        WAVELENGTH_NM,
        mode="path",
        resolution_px=64,
        samples_per_pixel=128,
        seed=3,
        keep_images_for=[0],
    )
    s = render_intensity(target, sun, obs, e, WAVELENGTH_NM, mode="single", resolution_px=256)
    excess = p.intensity_W_sr_nm.mean() - s.intensity_W_sr_nm.mean()
    sigma = np.sqrt((p.intensity_std_W_sr_nm**2).sum()) / len(WAVELENGTH_NM)
    # 6 sigma: the chance that a zero excess shows up this large is ~1e-9 (normal), ~1e-3
    # with the 8-pass Student-t error estimate.
    assert excess > 6 * sigma
    # The kept hyperspectral image adds up to the intensity; its depth map matches the
    # single-scattering one (same orthographic rays) up to float32 rounding.
    img = p.images[0]
    total = img.radiance_W_m2_sr_nm.sum(axis=(0, 1)) * img.pixel_size_m**2
    np.testing.assert_allclose(total, p.intensity_W_sr_nm[0], rtol=1e-5)
    s64 = render_intensity(
        target, sun, obs, e, WAVELENGTH_NM, resolution_px=64, keep_images_for=[0]
    ).images[0]
    np.testing.assert_allclose(img.depth_m, s64.depth_m, atol=1e-4)
    np.testing.assert_array_equal(img.part_index, s64.part_index)


def test_white_concave_target_returns_all_intercepted_light_in_path_mode():
    # White furnace: with albedo 1 nothing is absorbed, so all power intercepted from the
    # Sun, E * A_proj(sun), leaves the target after any number of bounces:
    # integral of I over all observer directions = E * A_proj. Single scattering misses
    # the light that bounces between wing and bus (7 % here), path tracing must not.
    from speclight.render.camera import primary_rays
    from speclight.render.raycast import NumpyCaster

    white = Material("white", "lambertian", Reflectance.constant(1.0))
    target = box_wing(white)
    sun = np.array([0.2, 1.0, 0.3]) / np.linalg.norm([0.2, 1.0, 0.3])
    centre, radius = target.bounding_sphere()
    origin, direction, pixel_area = primary_rays(centre, radius, sun[None, :], 512)
    a_proj = NumpyCaster(target).intersect(origin, direction).hit.sum() * pixel_area
    x, wx = np.polynomial.legendre.leggauss(12)
    phi = (np.arange(24) + 0.5) * 2 * np.pi / 24
    mu, ph = np.meshgrid(x, phi, indexing="ij")
    st = np.sqrt(1 - mu**2)
    obs = np.stack([st * np.cos(ph), st * np.sin(ph), mu], -1).reshape(-1, 3)
    weight_sr = np.repeat(wx, 24) * 2 * np.pi / 24
    wl = np.array([550.0, 650.0])
    sun_n = np.tile(sun, (len(obs), 1))
    e = np.ones((len(obs), 2))
    p = render_intensity(
        target, sun_n, obs, e, wl, mode="path", resolution_px=32, samples_per_pixel=2, seed=4
    )
    s = render_intensity(target, sun_n, obs, e, wl, mode="single", resolution_px=64)
    returned = weight_sr @ p.intensity_W_sr_nm.mean(axis=1) / a_proj
    single = weight_sr @ s.intensity_W_sr_nm.mean(axis=1) / a_proj
    # Tolerance: 288-direction product quadrature of an integrand with kinks (faces and
    # two-sided wings switching visibility) is good to ~1 % (0.8 % seen with 16 spp), plus
    # three stated Monte Carlo standard errors (2 spp: ~0.6 %); A_proj at 512 px: < 0.1 %.
    sigma = np.sqrt(weight_sr**2 @ (p.intensity_std_W_sr_nm**2).mean(axis=1)) / a_proj
    quadrature_error = 0.01
    assert abs(returned - 1) < quadrature_error + 3 * sigma
    assert single < returned - 0.03


def test_path_smooth_plastic_plate_diffuse_base():
    # Off the glint a smooth-coated plastic plate shows its base:
    # I = rho_d (1 - F_i)(1 - F_o) / (eta^2 pi (1 - F_dr,int)) E A cos(theta_i) cos(theta_o)
    # (Weidlich & Wilkie 2007). Path mode's coated BSDF takes the index at each sampled
    # wavelength (render/bsdfs/path_coat.py); the reference below takes the mean index: n of
    # fused silica varies by 0.3 % over 500-700 nm, changing I by < 0.1 %.
    from speclight.target import plate, refractive_index

    rho_d = 0.6
    wl = np.arange(500.0, 701.0, 20.0)
    m = Material(
        "paint",
        "plastic",
        Reflectance.dielectric("SiO2"),
        diffuse_reflectance=Reflectance.constant(rho_d),
    )
    ti, to = np.radians([50.0, 70.0]), np.radians([10.0, 40.0])
    sun = np.stack([np.sin(ti), np.zeros(2), np.cos(ti)], 1)
    obs = np.stack([np.zeros(2), np.sin(to), np.cos(to)], 1)  # out of the mirror plane
    res = render_intensity(
        plate(1.0, 1.0, m),
        sun,
        obs,
        np.ones((2, len(wl))),
        wl,
        mode="path",
        resolution_px=32,
        samples_per_pixel=64,
        seed=5,
    )
    eta = float(np.mean(refractive_index("SiO2", wl).real))

    def fresnel(c, n):  # real index, Hecht eqs. 4.42-4.43; total internal reflection -> 1
        s2 = (1 - c**2) / n**2
        ct = np.sqrt(np.clip(1 - s2, 0, None))
        rs, rp = (c - n * ct) / (c + n * ct), (n * c - ct) / (n * c + ct)
        return np.where(s2 >= 1, 1.0, 0.5 * (rs**2 + rp**2))

    mu = (np.arange(20000) + 0.5) / 20000
    f_dr = 2 * np.mean(fresnel(mu, 1 / eta) * mu)
    f = rho_d * (1 - fresnel(np.cos(ti), eta)) * (1 - fresnel(np.cos(to), eta))
    ref = f / (eta**2 * np.pi * (1 - f_dr)) * np.cos(ti) * np.cos(to)
    sigma = np.sqrt((res.intensity_std_W_sr_nm**2).sum(axis=1)) / len(wl)
    # The mean index of the reference: I within 1e-3 (above).
    fit_error = 1e-3 * ref
    assert np.all(np.abs(res.intensity_W_sr_nm.mean(axis=1) - ref) < Z_MAX * sigma + fit_error)
