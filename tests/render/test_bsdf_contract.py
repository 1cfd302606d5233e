"""Contract test: every registered BSDF model through the same checks.

As Mitsuba's chi-square harness runs any BSDF through one test (``mitsuba.chi2.BSDFAdapter``
+ ``ChiSquareTest``), every form of every model of :mod:`speclight.target.bsdf_models`, with
each of its registry ``examples`` (reflectances at their largest where a number is accepted),
is held to:

1. reciprocity (Helmholtz): the single mode's BRDF (the channels summed as the renders sum
   them, :func:`speclight.render.laser_multibounce.fcos_spectral`) is the same with the
   light and view directions swapped;
2. energy (white furnace): the directional albedo a(theta_i) = int f cos(theta_o) dw is at
   most 1, integrated numerically over the hemisphere;
3. single vs path: where the model supports both modes, a flat plate (a convex target:
   single scattering is the whole answer) rendered in both agrees within the path mode's
   standard errors.

Adding a model to the registry adds it here. Run time: about 30 s on 2 cores.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from test_render_rgl import FILE_INTERP_TOL, write_lambert_rgl

from speclight.render import RenderSession, available_variants, render_intensity
from speclight.render.bsdfs import RENDERERS, material_bsdf
from speclight.render.laser_multibounce import fcos_spectral
from speclight.render.material_channels import ChannelLayout
from speclight.render.shading import SUN_COS, SUN_SOLID_ANGLE_SR, sun_disk_sin2
from speclight.target import Material, material_from_spec, plate
from speclight.target.bsdf_models import BSDF_FORMS, MEASURED_RGL, BsdfModel

WAVELENGTH_NM = np.array([400.0, 550.0, 700.0, 900.0])
VECTORISED = any(v.startswith(("llvm_", "cuda_")) for v in available_variants())
SPECTRAL = VECTORISED and any(
    v.startswith(("llvm_", "cuda_")) and v.endswith("_spectral") for v in available_variants()
)
#: Known failures, each with what it is and where it is followed up; strict: fixed, it fails.
KNOWN: dict[tuple[str, str], str] = {}


def _cases(check: str, modes: tuple[str, ...] = ("single",)) -> list:
    out = []
    for form in BSDF_FORMS:
        if not set(modes) <= set(form.modes):
            continue
        for i, example in enumerate(form.examples):
            marks = []
            if (form.label, check) in KNOWN:
                marks.append(pytest.mark.xfail(strict=True, reason=KNOWN[form.label, check]))
            if form is MEASURED_RGL:
                marks.append(
                    pytest.mark.skipif(
                        not SPECTRAL, reason="RGL needs a vectorised spectral variant"
                    )
                )
            out.append(pytest.param(form, example, marks=marks, id=f"{form.label}-{i}"))
    return out


@pytest.fixture(scope="module")
def white_rgl(tmp_path_factory: pytest.TempPathFactory) -> Path:
    # No RGL file ships with speclight: the RGL form's example file is a Lambertian one of
    # albedo 1 (test_render_rgl.py checks that Mitsuba's plugin reads it as such).
    path = tmp_path_factory.mktemp("rgl") / "white.bsdf"
    return write_lambert_rgl(path, [1.0, 1.0], [300.0, 1300.0])


def _material(form: BsdfModel, example: dict, rgl_file: Path) -> Material:
    spec = dict(example)
    if form is MEASURED_RGL:
        spec["brdf_table"] = str(rgl_file)
    m = material_from_spec("m", spec)
    if form.engines:  # Mitsuba evaluates it: in the variant a run would choose
        RenderSession.create("single", None, [m]).activate()
    return m


def _brdf(m: Material, s: np.ndarray, o: np.ndarray) -> np.ndarray:
    """The single mode's f(s -> o) (P, L) [sr-1] on a surface of normal +z."""
    layout = ChannelLayout(plate(1.0, 1.0, m))
    blocks = {k: layout.bsdfs[k].block_factor(WAVELENGTH_NM) for k in layout.block}
    n = np.tile([0.0, 0.0, 1.0], (len(s), 1))
    fcos = fcos_spectral(layout, blocks, WAVELENGTH_NM, np.zeros(len(s), int), n, s, o)
    return fcos / s[:, 2:3]


def _directions(rng: np.random.Generator, count: int) -> np.ndarray:
    """Unit vectors within 60 deg of the normal +z, uniform in solid angle."""
    cos = rng.uniform(0.5, 1.0, count)
    phi = rng.uniform(0.0, 2 * np.pi, count)
    sin = np.sqrt(1.0 - cos**2)
    return np.stack([sin * np.cos(phi), sin * np.sin(phi), cos], axis=1)


@pytest.mark.parametrize(("form", "example"), _cases("reciprocity"))
def test_brdf_is_reciprocal(form, example, white_rgl):
    # Helmholtz reciprocity f(s -> o) = f(o -> s) (e.g. Pharr, Jakob & Humphreys, PBRT 4th
    # ed., sec. 4.3.1) at random pairs and at mirror pairs (the peak of every lobe; a smooth
    # mirror is seen only there).
    m = _material(form, example, white_rgl)
    rng = np.random.default_rng(11)
    s = np.concatenate([_directions(rng, 300), _directions(rng, 60)])
    o = np.concatenate([_directions(rng, 300), s[300:] * [-1.0, -1.0, 1.0]])  # mirrors
    forward, backward = _brdf(m, s, o), _brdf(m, o, s)
    assert np.any(forward[300:] > 0), "the mirror pairs must see the lobe"
    if form is MEASURED_RGL:
        # the test file holds rho / pi within FILE_INTERP_TOL * rho / pi in f cos (rho = 1)
        tol = FILE_INTERP_TOL / np.pi * (1 / s[:, 2] + 1 / o[:, 2])[:, None]
    else:
        # the same formulas on cosines that differ by rounding (the half vector is the same):
        # float64 rounding through the model (measured 2e-16 for the analytic models, 7e-14
        # for a lab table through the arccos of the rounded cosines)
        tol = 1e-12 * np.maximum(forward, backward)
    assert np.all(np.abs(forward - backward) <= tol)


#: Quadrature of the white furnace: Gauss-Legendre in the angle theta' from the mirror
#: direction, split at the solar disk's radius (the edge of a smooth mirror's glint), and
#: the trapezoid rule (spectral for periodic integrands) in the azimuth about it.
QUADRATURE = (12, 96, 128)
INCIDENCE_DEG = (0.0, 30.0, 60.0, 80.0)


def _albedo(m: Material, theta_i: float, n_glint: int, n_rest: int, n_phi: int) -> np.ndarray:
    """Directional albedo (L,) int f(s -> o) cos(theta_o) dw_o over the hemisphere."""
    s = np.array([np.sin(theta_i), 0.0, np.cos(theta_i)])
    r = np.array([-s[0], 0.0, s[2]])  # mirror direction of s
    t1 = np.array([np.cos(theta_i), 0.0, np.sin(theta_i)])
    t2 = np.cross(r, t1)
    edge = np.arccos(SUN_COS)
    x1, w1 = np.polynomial.legendre.leggauss(n_glint)
    x2, w2 = np.polynomial.legendre.leggauss(n_rest)
    theta = np.r_[edge / 2 * (x1 + 1), edge + (np.pi - edge) / 2 * (x2 + 1)]
    w_theta = np.r_[edge / 2 * w1, (np.pi - edge) / 2 * w2] * np.sin(theta)
    phi = 2 * np.pi * np.arange(n_phi) / n_phi
    th, ph = (a.ravel() for a in np.meshgrid(theta, phi, indexing="ij"))
    o = np.cos(th)[:, None] * r + np.sin(th)[:, None] * (
        np.cos(ph)[:, None] * t1 + np.sin(ph)[:, None] * t2
    )
    weight = np.repeat(w_theta, n_phi) * (2 * np.pi / n_phi) * np.clip(o[:, 2], 0.0, None)
    f = _brdf(m, np.tile(s, (len(o), 1)), o)
    return np.asarray(weight @ f)


def _albedo_with_error(m: Material, theta_i: float) -> tuple[np.ndarray, float]:
    """The albedo on the finer quadrature and its error estimate: the change from the
    coarser one (halved steps; at least second-order convergence, so the change bounds
    the finer result's error)."""
    coarse = _albedo(m, theta_i, *QUADRATURE)
    fine = _albedo(m, theta_i, *(2 * q for q in QUADRATURE))
    return fine, float(np.max(np.abs(fine - coarse)))


def test_white_furnace_quadrature_integrates_lamberts_law():
    # The harness itself: a white Lambertian surface reflects everything, a = 1 exactly.
    m = material_from_spec("white", {"bsdf": "lambertian", "reflectance": 1.0})
    for theta in np.radians(INCIDENCE_DEG):
        albedo, error = _albedo_with_error(m, theta)
        assert error < 1e-3
        assert np.all(np.abs(albedo - 1.0) <= error + 1e-12)


@pytest.mark.parametrize(("form", "example"), _cases("white furnace"))
def test_white_furnace_albedo_is_at_most_one(form, example, white_rgl):
    # Energy conservation: a surface lit by a white furnace reflects at most what it gets.
    m = _material(form, example, white_rgl)
    for theta in np.radians(INCIDENCE_DEG):
        albedo, error = _albedo_with_error(m, theta)
        assert error < 2e-2, "the quadrature does not resolve the model"
        assert np.all(albedo <= 1.0 + error + 1e-12), (np.degrees(theta), albedo, error)


#: z-test bound: 4 standard errors of the 8-pass estimate (Student t, 7 dof: fails by chance
#: in ~5e-3 of seeds; seeds are fixed, so a pass is reproducible).
Z_MAX = 4.0
#: Path mode's solar disk is 0.23 % smaller in solid angle than the single mode's
#: (speclight.render.shading.sun_disk_sin2): a mirror's glint radiance is that much higher.
DISK_BIAS = SUN_SOLID_ANGLE_SR / (np.pi * sun_disk_sin2()) - 1.0
#: Documented differences between a model's single and path implementations, relative.
#: Plastic: single mode bins the base bilinearly on 33 cosine nodes (h = 1/32), path mode
#: interpolates the coat transmittance linearly on 64 (h = 1/63); the interpolation error of
#: T(mu_i) T(mu_o) is at most 2 (h32^2 + h63^2) / 8 max|T''| / min T, with |T''| <= 1.8 on
#: the coats here at mu >= 0.5 (computed on the nodes; 2.5 taken) and T >= 0.86.
MODE_DIFFERENCE = {"plastic": 2 * ((1 / 32) ** 2 + (1 / 63) ** 2) / 8 * 2.5 / 0.86}
PLATE_WL_NM = np.arange(500.0, 701.0, 40.0)


def _plate_geometry() -> tuple[np.ndarray, np.ndarray]:
    """A glint (mirror pair at 30 deg) and an off-specular pair (30 deg in, 50 deg out)."""
    a, b, az = np.radians(30.0), np.radians(50.0), np.radians(120.0)
    sun = np.array([[np.sin(a), 0.0, np.cos(a)]] * 2)
    obs = np.array(
        [[-np.sin(a), 0.0, np.cos(a)], [np.sin(b) * np.cos(az), np.sin(b) * np.sin(az), np.cos(b)]]
    )
    return sun, obs


@pytest.mark.skipif(not SPECTRAL, reason="path mode needs a vectorised spectral variant")
@pytest.mark.parametrize(("form", "example"), _cases("single vs path", ("single", "path")))
def test_single_and_path_agree_on_a_plate(form, example, white_rgl):
    m = _material(form, example, white_rgl)
    bsdf = material_bsdf(m)
    target = plate(1.0, 1.0, m)
    sun, obs = _plate_geometry()
    e = np.ones((2, len(PLATE_WL_NM)))
    # A point Sun never reaches the observer through a mirror: those are lit by the disk.
    p = render_intensity(
        target, sun, obs, e, PLATE_WL_NM, mode="path", resolution_px=32, samples_per_pixel=64,
        seed=5, solar_disk=bsdf.mirror_lobe(),
    )  # fmt: skip
    s = render_intensity(target, sun, obs, e, PLATE_WL_NM, resolution_px=64, keep_images_for=[0, 1])
    # Path mode integrates each pixel's area (box filter); the single mode counts pixel
    # centres: its intensity is rescaled from its pixels' area (its part map) to the
    # plate's exact projected area, so that only the BRDFs are compared.
    for k in (0, 1):
        img = s.images[k]
        covered = np.count_nonzero(img.part_index >= 0) * img.pixel_size_m**2
        s.intensity_W_sr_nm[k] *= obs[k, 2] / covered
    i_s, i_p = s.intensity_W_sr_nm.mean(axis=1), p.intensity_W_sr_nm.mean(axis=1)
    sigma = np.sqrt((p.intensity_std_W_sr_nm**2).sum(axis=1)) / len(PLATE_WL_NM)
    bias = (abs(DISK_BIAS) if bsdf.mirror_lobe() else 0.0) + MODE_DIFFERENCE.get(form.label, 0.0)
    assert np.any(i_s > 0)
    assert np.all(np.abs(i_p - i_s) <= Z_MAX * sigma + bias * i_s), (i_p / i_s - 1, sigma / i_s)


def test_every_model_has_a_renderer():
    # the render side's table and the registry name the same models (forms)
    assert set(RENDERERS) == {form.label for form in BSDF_FORMS}
