"""RGL measured materials (.bsdf, Mitsuba's ``measured`` plugin) in single and path modes.

No RGL file ships with speclight, so the tests write one: a Lambertian surface of albedo rho
in the Dupuy & Jakob 2018 parameterisation (doi:10.1145/3272127.3275059) as Mitsuba 3's
``measured`` plugin reads it (src/bsdfs/measured.cpp): a uniform VNDF, whose inverse warp is
the identity, so the ``spectra`` sample grid is the microfacet-normal grid u = (sqrt(2
theta_m / pi), (phi_m - phi_i + pi) / (2 pi)), holding f cos(theta_o) 4 sigma / D with the
tabulated D (``ndf``) and sigma, which the plugin multiplies back (``jacobian`` = 1). Mitsuba,
an independent implementation, must then return rho cos(theta_o) / pi, and renders must follow
the Lambert closed forms.
"""

from pathlib import Path

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.render import available_variants, render_intensity, rgl
from speclight.target import Material, Reflectance, cube, plate, sphere
from speclight.target.rgl_file import write_tensor_file

pytestmark = pytest.mark.skipif(
    not any(v.startswith(("llvm_", "cuda_")) and v.endswith("_spectral")
            for v in available_variants()),
    reason="RGL materials need a vectorised Mitsuba spectral variant",
)  # fmt: skip

#: Sample grid of the test file: N x N microfacet-normal nodes, T incident elevations.
N_GRID, N_THETA = 65, 33
#: Bilinear interpolation error of the file, relative to rho / pi, for directions within 60 deg
#: of the normal: h^2 / 8 max|f''| summed over the axes. Along u_phi (h = 1/64)
#: d2 cos(theta_o) / du2 <= (2 pi)^2 -> 1.2e-3; along u_theta (h = 1/64, theta_m = pi u^2 / 2)
#: <= pi^2 -> 3e-4; along theta_i (h = pi / 64, f'' <= 2) -> 6e-4. Sum 2.1e-3, rounded up.
FILE_INTERP_TOL = 5e-3
#: Relative rounding of a float32 Dr.Jit evaluation (a few ulp of 1.2e-7).
FLOAT32_ROUNDING = 1e-6
#: Lambert sphere law tolerance (issue 3): the file error above (it enters the disk integral
#: with weights < 1) plus the pixel-centre error of a 256 px sphere (< 5e-4 at phase
#: <= 120 deg for the built-in lambertian model).
SPHERE_TOL = 5e-3
SPHERE_PX = 256
#: Path mode z-test bound (see test_render_path.py).
Z_MAX = 4.0


def write_lambert_rgl(path: Path, albedo, wavelength_nm) -> Path:
    """An RGL tensor file of a Lambertian BRDF rho(lambda) / pi (see the module doc)."""
    rho = np.asarray(albedo, dtype=float)
    theta_i = np.linspace(0.0, np.pi / 2, N_THETA)
    u = np.linspace(0.0, 1.0, N_GRID)
    theta_m = (np.pi / 2) * u[None, :] ** 2  # last (x) axis: elevation of the normal
    phi_m = 2 * np.pi * u[:, None] - np.pi  # y axis: azimuth relative to the incidence
    m = np.stack(
        np.broadcast_arrays(
            np.sin(theta_m) * np.cos(phi_m), np.sin(theta_m) * np.sin(phi_m), np.cos(theta_m)
        ),
        axis=-1,
    )
    ndf = np.broadcast_to(1.0 + u[None, :], (N_GRID, N_GRID))  # D(u): any positive table
    sigma_of = lambda t: 0.5 + 0.5 * t / np.pi  # noqa: E731 (smooth in theta and in u)
    sigma = np.broadcast_to(sigma_of(np.pi / 2 * u[None, :] ** 2), (N_GRID, N_GRID))
    spectra = np.zeros((1, N_THETA, len(rho), N_GRID, N_GRID))
    for t, ti in enumerate(theta_i):
        wi = np.array([np.sin(ti), 0.0, np.cos(ti)])
        cos_o = 2 * (m @ wi) * m[..., 2] - wi[2]  # reflection of wi about m
        fcos = np.maximum(cos_o, 0.0) / np.pi
        spectra[0, t] = rho[:, None, None] * (fcos * 4 * sigma_of(ti) / ndf)[None]
    f32 = np.float32
    write_tensor_file(
        path,
        {
            "description": np.frombuffer(b"Lambertian test material", np.uint8),
            "theta_i": theta_i.astype(f32),
            "phi_i": np.zeros(1, f32),
            "wavelengths": np.asarray(wavelength_nm, f32),
            "ndf": ndf.astype(f32),
            "sigma": sigma.astype(f32),
            "vndf": np.ones((1, N_THETA, 2, 2), f32),
            "luminance": (spectra.mean(axis=2) + 1e-6).astype(f32),
            "spectra": spectra.astype(f32),
            "jacobian": np.ones(1, np.uint8),
        },
    )
    return path


@pytest.fixture(scope="module")
def grey(tmp_path_factory) -> Path:
    return write_lambert_rgl(tmp_path_factory.mktemp("rgl") / "grey.bsdf", [0.6, 0.6], [300, 1300])


@pytest.fixture(scope="module")
def coloured(tmp_path_factory) -> tuple[Path, np.ndarray, np.ndarray]:
    nodes, rho = np.array([400.0, 600.0, 800.0]), np.array([0.2, 0.5, 0.4])
    path = write_lambert_rgl(tmp_path_factory.mktemp("rgl") / "colour.bsdf", rho, nodes)
    return path, nodes, rho


def _phase_dirs(phase_deg):
    a = np.radians(np.asarray(phase_deg, dtype=float))
    sun = np.tile([0.0, 0.0, 1.0], (len(a), 1))
    return sun, np.stack([np.sin(a), np.zeros_like(a), np.cos(a)], axis=1)


def _lambert_sphere(rho, phase_deg):
    # Lambert sphere I(a) = (2 / (3 pi)) rho E R^2 [sin a + (pi - a) cos a] (Russell 1916).
    a = np.radians(np.asarray(phase_deg, dtype=float))
    return 2 / (3 * np.pi) * rho * (np.sin(a) + (np.pi - a) * np.cos(a))


def test_mitsuba_measured_plugin_reads_the_written_file_as_lambertian(grey, monkeypatch):
    rng = np.random.default_rng(3)
    n = 400
    cos_i, cos_o = rng.uniform(0.5, 1.0, n), rng.uniform(0.5, 1.0, n)  # within 60 deg
    phi = rng.uniform(0, 2 * np.pi, n)
    sin_i, sin_o = np.sqrt(1 - cos_i**2), np.sqrt(1 - cos_o**2)
    cos_phase = cos_i * cos_o + sin_i * sin_o * np.cos(phi)
    sun, obs = rgl.local_directions(cos_i, cos_o, cos_phase)
    # the local frame reproduces the three angles it was given
    np.testing.assert_allclose(sun[:, 2], cos_i, atol=1e-12)
    np.testing.assert_allclose(obs[:, 2], cos_o, atol=1e-12)
    np.testing.assert_allclose(np.einsum("nk,nk->n", sun, obs), cos_phase, atol=1e-9)
    spectral = _spectral_variants()[-1]
    f_cos = rgl.eval_plugin(str(grey), sun, obs, spectral)  # (n, 2): both wavelength nodes
    ref = 0.6 / np.pi * cos_i
    assert np.max(np.abs(f_cos - ref[:, None])) < FILE_INTERP_TOL * 0.6 / np.pi
    # evaluating in several Dr.Jit batches changes nothing
    monkeypatch.setattr(rgl, "EVAL_BATCH", 7)
    batched = rgl.eval_plugin(str(grey), sun, obs, spectral)
    np.testing.assert_allclose(batched, f_cos, rtol=FLOAT32_ROUNDING)
    # below the horizon the plugin returns 0
    sun_below = sun * np.array([1.0, 1.0, -1.0])
    assert np.all(rgl.eval_plugin(str(grey), sun_below, obs, spectral) == 0.0)


def _spectral_variants():
    fast = [v for v in available_variants() if v.startswith(("cuda_", "llvm_"))]
    return ["auto", *[v for v in fast if v.endswith("_spectral")][:1]]


@pytest.mark.parametrize("variant", _spectral_variants())
def test_single_rgl_sphere_follows_the_lambert_phase_law(grey, variant):
    # The run's one variant is a spectral one: rays are cast in it and the plugin runs in it.
    phase = np.array([0.0, 30.0, 60.0, 90.0, 120.0])
    sun, obs = _phase_dirs(phase)
    wl = np.array([350.0, 550.0, 1200.0])
    m = Material("rgl", "measured", Reflectance.constant(1.0), brdf_table=str(grey))
    res = render_intensity(
        sphere(1.0, m),
        sun,
        obs,
        np.ones((len(phase), len(wl))),
        wl,
        resolution_px=SPHERE_PX,
        variant=variant,
        keep_images_for=[2],
    )
    assert res.variant.endswith("_spectral")
    ref = _lambert_sphere(0.6, phase)
    np.testing.assert_allclose(res.intensity_W_sr_nm, ref[:, None] * np.ones(3), rtol=SPHERE_TOL)
    img = res.images[2]
    total = img.radiance_W_m2_sr_nm.sum(axis=(0, 1)) * img.pixel_size_m**2
    np.testing.assert_allclose(total, res.intensity_W_sr_nm[2], rtol=1e-9)


def test_single_rgl_spectrum_is_the_plugins_linear_interpolation(coloured):
    # The plugin interpolates the tabulated spectra linearly in wavelength and holds the end
    # values outside the file's range (Marginal2D parameter clamping), i.e. np.interp.
    path, nodes, rho = coloured
    wl = np.arange(300.0, 1001.0, 25.0)
    sun, obs = _phase_dirs([50.0])
    e = np.linspace(1.0, 2.0, len(wl))[None, :]
    full = Material("rgl", "measured", Reflectance.constant(1.0), brdf_table=str(path))
    half = Material("rgl", "measured", Reflectance.constant(0.5), brdf_table=str(path))
    i_full = render_intensity(sphere(1.0, full), sun, obs, e, wl, resolution_px=SPHERE_PX)
    i_half = render_intensity(sphere(1.0, half), sun, obs, e, wl, resolution_px=SPHERE_PX)
    ref = _lambert_sphere(np.interp(wl, nodes, rho), 50.0) * e[0]
    np.testing.assert_allclose(i_full.intensity_W_sr_nm[0], ref, rtol=SPHERE_TOL)
    # a constant reflectance scales the measured BRDF
    np.testing.assert_allclose(i_half.intensity_W_sr_nm, 0.5 * i_full.intensity_W_sr_nm, rtol=1e-12)


def test_single_rgl_plate_follows_lamberts_cosine_law(grey):
    # Flat plate: I = (rho / pi) E A cos(theta_i) cos(theta_o); the pixel-outline bound as in
    # test_render_single_closed_forms.py, plus the file's interpolation error.
    w, h, res_px = 2.0, 1.0, 128
    th_i, th_o, az = np.radians([30.0, 10.0, 55.0]), np.radians([45.0, 60.0, 20.0]), [1.0, 2.5, 4.0]
    sun = np.stack([np.sin(th_i), np.zeros(3), np.cos(th_i)], axis=1)
    obs = np.stack([np.sin(th_o) * np.cos(az), np.sin(th_o) * np.sin(az), np.cos(th_o)], axis=1)
    m = Material("rgl", "measured", Reflectance.constant(1.0), brdf_table=str(grey))
    res = render_intensity(plate(w, h, m), sun, obs, np.ones((3, 1)), [550.0], resolution_px=res_px)
    ref = 0.6 / np.pi * w * h * np.cos(th_i) * np.cos(th_o)
    pitch = 2 * np.hypot(w / 2, h / 2) / res_px
    bound = 2 * (w + h) * pitch / (w * h * np.cos(th_o)) + FILE_INTERP_TOL / np.cos(th_i)
    assert np.all(np.abs(res.intensity_W_sr_nm[:, 0] / ref - 1) < bound)


def test_rgl_faces_share_the_channel_layout_with_plastic_and_ggx_faces(grey):
    # Cube with RGL faces beside plastic (a block of its own) and GGX faces: replacing the
    # RGL faces by the built-in lambertian model (checked against closed forms in
    # test_render_single_closed_forms.py) must change nothing beyond the file's error.
    rgl_m = Material("rgl", "measured", Reflectance.constant(1.0), brdf_table=str(grey))
    lam = Material("lam", "lambertian", Reflectance.constant(0.6))
    coat = Material(
        "coat",
        "plastic",
        Reflectance.dielectric("SiO2"),
        diffuse_reflectance=Reflectance.constant(0.5),
        roughness=0.2,
    )
    al = Material("al", "ggx", Reflectance.conductor("Al"), roughness=0.3)
    rng = np.random.default_rng(0)
    sun, obs = rng.normal(size=(4, 3)), rng.normal(size=(4, 3))
    sun /= np.linalg.norm(sun, axis=1, keepdims=True)
    obs /= np.linalg.norm(obs, axis=1, keepdims=True)
    wl = np.arange(400.0, 901.0, 100.0)

    def render(m):
        faces = {"+x": m, "-x": coat, "+y": m, "-y": al, "+z": coat, "-z": m}
        e = np.ones((4, len(wl)))
        return render_intensity(cube(1.0, faces), sun, obs, e, wl, resolution_px=96)

    a, b = render(rgl_m).intensity_W_sr_nm, render(lam).intensity_W_sr_nm
    assert np.max(np.abs(a - b)) < FILE_INTERP_TOL * np.max(b)


def test_path_rgl_sphere_follows_the_lambert_law_within_monte_carlo_error(grey):
    # Path mode loads the file with Mitsuba's 'measured' plugin; reflectance 0.5 goes through
    # Mitsuba's blendbsdf with a black BSDF. A convex target never lights itself, so the path
    # tracer must reproduce the Lambert sphere (0.5 rho) in expectation.
    phase = np.array([0.0, 60.0, 120.0])
    sun, obs = _phase_dirs(phase)
    wl = np.arange(400.0, 801.0, 50.0)
    m = Material("rgl", "measured", Reflectance.constant(0.5), brdf_table=str(grey))
    res = render_intensity(
        sphere(1.0, m),
        sun,
        obs,
        np.ones((3, len(wl))),
        wl,
        mode="path",
        resolution_px=48,
        samples_per_pixel=32,
        seed=5,
    )
    ref = _lambert_sphere(0.5 * 0.6, phase)
    i, sd = res.intensity_W_sr_nm, res.intensity_std_W_sr_nm
    assert np.all(sd > 0)
    sigma_mean = np.sqrt((sd**2).sum(axis=1)) / len(wl)
    assert np.all(np.abs(i.mean(axis=1) - ref) < Z_MAX * sigma_mean + FILE_INTERP_TOL * ref)


@pytest.mark.parametrize("variant", ["numpy", "llvm_ad_rgb"])
def test_single_rgl_refuses_a_variant_that_cannot_evaluate_it(grey, variant):
    # One variant per run: a ray-casting-only variant cannot run the plugin, and speclight
    # no longer switches the process-wide variant behind the user's back.
    if variant != "numpy" and variant not in available_variants():
        pytest.skip(f"{variant} not available here")
    m = Material("rgl", "measured", Reflectance.constant(1.0), brdf_table=str(grey))
    sun, obs = _phase_dirs([30.0])
    with pytest.raises(InputError, match="spectral variant") as err:
        render_intensity(
            sphere(1.0, m),
            sun,
            obs,
            np.ones((1, 2)),
            np.array([500.0, 600.0]),
            resolution_px=32,
            variant=variant,
        )
    assert err.value.field == "render.variant"


def test_rgl_material_and_a_laser_share_one_variant(grey):
    # Issue 8: a run with an RGL material and a laser used to mix *_spectral (Sun render) and
    # *_rgb (laser render). The session hands both the same variant and the same caster.
    import mitsuba as mi

    from speclight.render.laser_returns import LaserLight, render_laser_returns
    from speclight.render.session import RenderSession

    m = Material("rgl", "measured", Reflectance.constant(1.0), brdf_table=str(grey))
    target = sphere(1.0, m)
    session = RenderSession.create("single", None, target.materials)
    assert session.variant.endswith("_spectral")
    wl = np.array([500.0, 532.0, 600.0])
    sun, obs = _phase_dirs([0.0])
    sun_render = render_intensity(
        target, sun, obs, np.ones((1, 3)), wl, resolution_px=SPHERE_PX, session=session
    )
    assert sun_render.variant == session.variant == mi.variant()
    light = LaserLight(obs, np.array([1]), np.ones((1, 1)))  # coaxial laser at 532 nm
    laser = render_laser_returns(target, obs, [light], wl, resolution_px=SPHERE_PX, session=session)
    assert mi.variant() == session.variant  # nothing switched it
    # the same Lambertian sphere at zero phase, lit by the laser or by the Sun
    np.testing.assert_allclose(
        laser.intensity_W_sr_nm(0)[0, 0], sun_render.intensity_W_sr_nm[0, 1], rtol=1e-9
    )
    np.testing.assert_allclose(
        laser.intensity_W_sr_nm(0)[0, 0], _lambert_sphere(0.6, 0.0), rtol=SPHERE_TOL
    )
