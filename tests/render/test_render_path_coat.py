"""Path mode's spectral coated BSDF (render/bsdfs/path_coat.py) and sample loop
(render/path_sampling.py).

Run time: about 15 s on 2 cores.
"""

import gc
from types import SimpleNamespace

import numpy as np
import pytest

from speclight.render import available_variants, render_intensity
from speclight.render.session import RenderSession
from speclight.target import Material, Reflectance, box_wing, plate, sphere

pytestmark = pytest.mark.skipif(
    not any(v.endswith("_spectral") and not v.startswith("scalar") for v in available_variants()),
    reason="path mode tests need a vectorised Mitsuba spectral variant",
)
#: A z-test at 4 standard errors fails by chance in 6e-5 of runs (normal), ~5e-3 with the
#: 8-pass Student-t error estimate; seeds are fixed, so a pass is reproducible.
Z_MAX = 4.0
#: Relative rounding of float32 Dr.Jit kernels (the same samples, other launches).
FLOAT32_ROUNDING = 1e-6


def _mi():
    variant = next(
        v
        for v in available_variants()
        if v.endswith("_spectral") and v.startswith(("llvm_", "cuda_"))
    )
    return RenderSession.create("path", variant, []).activate()


def _bsdf(mi, material, lo=400.0, hi=800.0):
    from speclight.render.bsdfs.path_coat import coat_tables, coated_diffuse

    return coated_diffuse(mi, coat_tables(material, lo, hi))


def _interaction(mi, wi, wavelengths, n=1):
    import drjit as dr

    si = dr.zeros(mi.SurfaceInteraction3f, n)
    si.wi = mi.Vector3f(*[float(x) for x in wi])
    si.wavelengths = mi.Spectrum(*[float(w) for w in wavelengths])
    si.sh_frame = mi.Frame3f(mi.Vector3f(0.0, 0.0, 1.0))
    return si


def _hemisphere(n_theta=400, n_phi=400):
    th = (np.arange(n_theta) + 0.5) * (np.pi / 2) / n_theta
    ph = (np.arange(n_phi) + 0.5) * 2 * np.pi / n_phi
    t, p = np.meshgrid(th, ph, indexing="ij")
    d = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1).reshape(-1, 3)
    return d, (np.sin(t) * (np.pi / 2 / n_theta) * (2 * np.pi / n_phi)).ravel()


class _Index:
    """A coat of refractive index 1 (no interface): a stand-in for a Reflectance."""

    kind = "dielectric"

    def eta(self, wl):
        return np.ones(np.shape(wl), complex)


def test_coat_of_index_one_is_lambertian():
    # n = 1: F = 0, T = 1, F_dr,int = 0, so f = rho / pi (Weidlich & Wilkie 2007 with no
    # interface); every sample's weight f cos / pdf is rho exactly (cosine sampling), and
    # the specular lobe is never chosen.
    import drjit as dr

    mi = _mi()
    rho = 0.7
    m = SimpleNamespace(
        reflectance=_Index(), diffuse_reflectance=Reflectance.constant(rho), roughness=None
    )
    b = _bsdf(mi, m)
    wi = np.array([np.sin(0.6), 0.0, np.cos(0.6)])
    wo = mi.Vector3f(0.0, float(np.sin(1.1)), float(np.cos(1.1)))
    si = _interaction(mi, wi, [450.0, 550.0, 650.0, 750.0])
    value, pdf = b.eval_pdf(mi.BSDFContext(), si, wo)
    np.testing.assert_allclose(np.array(value).ravel(), rho / np.pi * np.cos(1.1), rtol=1e-6)
    np.testing.assert_allclose(np.array(pdf).ravel(), np.cos(1.1) / np.pi, rtol=1e-6)
    n = 4096
    si = _interaction(mi, wi, [450.0, 550.0, 650.0, 750.0], n)
    rng = np.random.default_rng(1)
    u = rng.random((3, n))
    bs, weight = b.sample(
        mi.BSDFContext(), si, mi.Float(u[0]), mi.Point2f(mi.Float(u[1]), mi.Float(u[2]))
    )
    np.testing.assert_allclose(np.array(weight), rho, rtol=1e-5)
    assert dr.all(bs.sampled_type == mi.UInt32(+mi.BSDFFlags.DiffuseReflection))


@pytest.mark.parametrize("roughness", [None, 0.3], ids=["smooth", "rough"])
def test_sampling_agrees_with_evaluation(roughness):
    # The mean sample weight (f cos / pdf) is the directional albedo, which must equal the
    # hemispherical integral of eval (f cos) plus, for a smooth coat, the mirror's F(theta_i);
    # and the pdf integrates to the probability of the lobes that stay above the surface.
    # Kapton's index varies with wavelength (1.82 to 1.73 over the four wavelengths used).
    import drjit as dr

    mi = _mi()
    m = Material(
        "mli",
        "plastic",
        Reflectance.dielectric("Kapton"),
        roughness=roughness,
        diffuse_reflectance=Reflectance.constant(0.5),
    )
    b = _bsdf(mi, m)
    wl = [420.0, 520.0, 640.0, 780.0]
    theta_i = 0.5
    wi = np.array([np.sin(theta_i), 0.0, np.cos(theta_i)])
    d, dw = _hemisphere()
    si = _interaction(mi, wi, wl, len(d))
    wo = mi.Vector3f(mi.Float(d[:, 0]), mi.Float(d[:, 1]), mi.Float(d[:, 2]))
    value, pdf = b.eval_pdf(mi.BSDFContext(), si, wo)
    albedo_eval = np.array(value) @ dw  # (4,) integral of f cos over the hemisphere
    pdf_total = float(np.array(pdf) @ dw)
    n = 1 << 18
    si = _interaction(mi, wi, wl, n)
    u = np.random.default_rng(2).random((3, n))
    bs, weight = b.sample(
        mi.BSDFContext(), si, mi.Float(u[0]), mi.Point2f(mi.Float(u[1]), mi.Float(u[2]))
    )
    w = np.array(weight)  # (4, n)
    delta = np.array(bs.sampled_type) == int(mi.BSDFFlags.DeltaReflection)
    eta = m.reflectance.eta(np.array(wl)).real
    c, s2 = np.cos(theta_i), np.sin(theta_i) ** 2 / eta**2
    ct = np.sqrt(1 - s2)
    f_i = 0.5 * (((c - eta * ct) / (c + eta * ct)) ** 2 + ((eta * c - ct) / (eta * c + ct)) ** 2)
    expected = albedo_eval + (f_i if roughness is None else 0.0)
    mean, se = w.mean(axis=1), w.std(axis=1) / np.sqrt(n)
    # quadrature of eval on 400 x 400 nodes: 2e-6 relative (against 800 x 800)
    assert np.all(np.abs(mean - expected) < Z_MAX * se + 1e-5 * expected), (mean, expected)
    # smooth: the pdf's integral is 1 - P(mirror); rough: 1 - P(lost), the visible-normal
    # samples reflected below the surface (weight 0); binomial errors
    lost = delta if roughness is None else np.all(w == 0.0, axis=0)
    p_lost = lost.mean()
    assert abs(pdf_total - (1.0 - p_lost)) < Z_MAX * np.sqrt(p_lost * (1 - p_lost) / n) + 1e-5
    assert dr.all(dr.isfinite(weight[0]))


def test_eval_matches_the_single_mode_plastic():
    # The single mode's rough plastic is checked against an independent closed form
    # (test_render_plastic_agreement.py); the BSDF must give the same f at a plate's
    # geometry: f = I_plastic / I_white / pi (white Lambertian plate, same pixels).
    alpha, rho, wl = 0.3, 0.6, np.array([550.0])
    m = Material(
        "paint",
        "plastic",
        Reflectance.dielectric("SiO2"),
        roughness=alpha,
        diffuse_reflectance=Reflectance.constant(rho),
    )
    ti, to, phi = np.radians(40.0), np.radians(30.0), np.radians(20.0)
    wi = np.array([np.sin(ti), 0.0, np.cos(ti)])
    wo = np.array([-np.sin(to) * np.cos(phi), np.sin(to) * np.sin(phi), np.cos(to)])
    white = Material("white", "lambertian", Reflectance.constant(1.0))
    e = np.ones((1, 1))
    i_p = render_intensity(plate(1.0, 1.0, m), wi[None], wo[None], e, wl, resolution_px=32)
    i_w = render_intensity(plate(1.0, 1.0, white), wi[None], wo[None], e, wl, resolution_px=32)
    f_single = i_p.intensity_W_sr_nm[0, 0] / i_w.intensity_W_sr_nm[0, 0] / np.pi
    mi = _mi()  # after the single-mode renders (they activate an RGB variant)
    b = _bsdf(mi, m, 540.0, 560.0)
    si = _interaction(mi, wo, [550.0] * 4)  # wi: towards the observer, wo: the Sun (symmetric)
    value = np.array(b.eval(mi.BSDFContext(), si, mi.Vector3f(*[float(x) for x in wi])))
    f_path = value[0, 0] / np.cos(ti)
    # single mode: bilinear base on 33 x 33 cosine nodes (< 2e-4); here float32 tables
    assert f_path == pytest.approx(f_single, rel=5e-4)


def _coated_box_wing():
    return box_wing(
        {
            "bus": Material(
                "mli",
                "plastic",
                Reflectance.dielectric("Kapton"),
                roughness=0.3,
                diffuse_reflectance=Reflectance.conductor("Au"),
            ),
            "wing_+y": Material(
                "cells",
                "plastic",
                Reflectance.dielectric("SiO2"),
                roughness=0.3,
                diffuse_reflectance=Reflectance.constant(0.3),
            ),
            "wing_-y": Material(
                "glass",
                "plastic",
                Reflectance.dielectric("SiO2"),
                diffuse_reflectance=Reflectance.constant(0.5),
            ),
            "antenna": Material("paint", "lambertian", Reflectance.constant(0.8)),
        }
    )


def _box_wing_geometry():
    sun = np.array([[0.2, 1.0, 0.3], [0.5, -0.6, 0.6]])
    obs = np.array([[0.3, 0.8, 0.2], [-0.2, -0.7, 0.7]])
    return (
        sun / np.linalg.norm(sun, axis=1, keepdims=True),
        obs / np.linalg.norm(obs, axis=1, keepdims=True),
    )


def test_spectral_coat_agrees_with_the_grouped_plastic_on_a_concave_target():
    # The previous model (Mitsuba's plastic / roughplastic, one coat index per group of
    # bins, with its F_dr,int compensated) and the spectral BSDF carry the same model:
    # multi-bounce renders of the coated box-wing (rough Kapton over gold, rough and smooth
    # glass over grey) agree within the Monte Carlo error per block of bins, plus the
    # grouped model's own deviations: its index error (|n - n_group| <= 0.002: coat Fresnel
    # within 0.7 % on the coat's share of I, < 1/2) and Mitsuba's rough-coat transmittance
    # table (up to 0.34 % off the model's on a plate seen at 70 deg, measured at 256 spp).
    from speclight.render.path import render_path

    target = _coated_box_wing()
    sun, obs = _box_wing_geometry()
    sun, obs = sun[:1], obs[:1]
    wl = np.arange(500.0, 801.0, 25.0)  # Kapton's n: 1.77-1.73 here, 8 groups of bins
    e = np.ones((1, len(wl)))
    session = RenderSession.create("path", None, target.materials)
    kw = dict(resolution_px=32, samples_per_pixel=64)
    a, sa, *_ = render_path(target, sun, obs, e, wl, session, seed=31, coat="spectral", **kw)
    b, sb, *_ = render_path(target, sun, obs, e, wl, session, seed=32, coat="grouped", **kw)
    group_error = 0.0035 + 0.0034
    for block in np.array_split(np.arange(len(wl)), 3):
        ia, ib = a[:, block].mean(axis=1), b[:, block].mean(axis=1)
        sigma = np.sqrt((sa[:, block] ** 2 + sb[:, block] ** 2).sum(axis=1)) / len(block)
        assert np.all(np.abs(ia - ib) < Z_MAX * sigma + group_error * ib), (ia / ib - 1, sigma / ib)


def test_spectral_coat_follows_kapton_index_like_the_single_mode():
    # A convex target: single scattering is the whole answer. Kapton's index varies by 0.25
    # over 350-950 nm; both modes must agree per block of bins within the Monte Carlo error
    # and the single mode's pixel error (1.5e-3 at 256 px, test_render_plastic_agreement.py).
    m = Material(
        "mli",
        "plastic",
        Reflectance.dielectric("Kapton"),
        roughness=0.2,
        diffuse_reflectance=Reflectance.conductor("Au"),
    )
    a = np.radians([40.0, 110.0])
    sun = np.tile([0.0, 0.0, 1.0], (2, 1))
    obs = np.stack([np.sin(a), np.zeros(2), np.cos(a)], 1)
    wl = np.arange(350.0, 951.0, 25.0)
    e = np.ones((2, len(wl)))
    kw = dict(resolution_px=48, samples_per_pixel=64, seed=33)
    p = render_intensity(sphere(1.0, m), sun, obs, e, wl, mode="path", **kw)
    s = render_intensity(sphere(1.0, m), sun, obs, e, wl, resolution_px=256)
    for block in np.array_split(np.arange(len(wl)), 5):
        ip = p.intensity_W_sr_nm[:, block].mean(axis=1)
        i_s = s.intensity_W_sr_nm[:, block].mean(axis=1)
        sigma = np.sqrt((p.intensity_std_W_sr_nm[:, block] ** 2).sum(axis=1)) / len(block)
        assert np.all(np.abs(ip - i_s) < Z_MAX * sigma + 1.5e-3 * i_s), (ip / i_s - 1, sigma / i_s)


def test_one_launch_per_epoch_reproducible_with_progress_per_epoch():
    # Whatever the materials (here four, three of them coated), an epoch is one Dr.Jit
    # kernel launch; the same seed gives the same result bit for bit (sums in a fixed order);
    # on_epoch is called once per epoch.
    import drjit as dr

    from speclight.render.path import render_path

    target = _coated_box_wing()
    sun, obs = _box_wing_geometry()
    sun, obs = np.concatenate([sun, sun[::-1]]), np.concatenate([obs, obs])
    wl = np.arange(400.0, 801.0, 50.0)
    e = np.ones((len(sun), len(wl)))
    session = RenderSession.create("path", None, target.materials)
    kw = dict(resolution_px=16, samples_per_pixel=16, seed=7)

    def launches(n: int) -> tuple[int, np.ndarray, int]:
        # The render kernels of this run: the ray-tracing launches (thousands of operations),
        # told from the few tiny set-up kernels (a handful of operations on a few lanes, one
        # of them evaluated now and then by Dr.Jit's own housekeeping).
        calls = []
        gc.collect()
        dr.eval()
        dr.sync_thread()
        dr.set_flag(dr.JitFlag.KernelHistory, True)
        dr.kernel_history()
        out = render_path(target, sun[:n], obs[:n], e[:n], wl, session, on_epoch=calls.append, **kw)
        jit = [k for k in dr.kernel_history() if k.get("type") == dr.KernelType.JIT]
        dr.set_flag(dr.JitFlag.KernelHistory, False)
        renders = sum(1 for k in jit if k.get("operation_count", 0) > 1000)
        assert all(k.get("size", 0) <= 1024 for k in jit if k.get("operation_count", 0) <= 1000)
        return renders, out[0], len(calls)

    launches(1)  # kernels compiled
    one, first, calls_one = launches(1)
    four, again, calls_four = launches(4)
    assert (one, four) == (1, 4)
    assert (calls_one, calls_four) == (1, 4)
    np.testing.assert_allclose(again[:1], first, rtol=FLOAT32_ROUNDING)


def test_epochs_split_over_launches_agree_with_one_launch(monkeypatch):
    # An epoch with more samples than MAX_LANES is split into several launches, with
    # boundaries inside passes: the result is the same estimate (statistically), and a kept
    # image still adds up to the intensity.
    import speclight.render.path_sampling as sampling

    m = Material("paint", "lambertian", Reflectance.constant(0.6))
    target = box_wing(m)
    sun, obs = _box_wing_geometry()
    wl = np.array([500.0, 600.0, 700.0])
    e = np.ones((2, 3))
    kw = dict(mode="path", resolution_px=24, samples_per_pixel=32)
    a = render_intensity(target, sun, obs, e, wl, seed=41, **kw)
    monkeypatch.setattr(sampling, "MAX_LANES", 24 * 24 * 4 * 3 + 17)  # 5.3 launches per epoch
    b = render_intensity(target, sun, obs, e, wl, seed=42, keep_images_for=[1], **kw)
    ia, ib = a.intensity_W_sr_nm.mean(axis=1), b.intensity_W_sr_nm.mean(axis=1)
    sigma = np.sqrt((a.intensity_std_W_sr_nm**2 + b.intensity_std_W_sr_nm**2).sum(axis=1)) / 3
    assert np.all(np.abs(ia - ib) < Z_MAX * sigma)
    img = b.images[1]
    total = img.radiance_W_m2_sr_nm.sum(axis=(0, 1)) * img.pixel_size_m**2
    np.testing.assert_allclose(total, b.intensity_W_sr_nm[1], rtol=1e-9)


@pytest.mark.parametrize("solar_disk", [False, True], ids=["point-sun", "solar-disk"])
def test_frozen_launches_equal_traced_launches(monkeypatch, solar_disk):
    # The launch is frozen (dr.freeze: recorded on the first epoch, replayed with each
    # epoch's Sun, rays and seed). Replays must give what tracing every launch gives, bit for
    # bit, over epochs with different Suns and over launches of different widths (an epoch
    # split in 2.4 launches), with the Sun a directional emitter or a far sphere.
    import drjit as dr

    import speclight.render.path as path
    import speclight.render.path_sampling as sampling

    if not hasattr(dr, "freeze"):
        pytest.skip("this Dr.Jit has no frozen functions")
    target = _coated_box_wing()
    sun, obs = _box_wing_geometry()
    sun, obs = np.concatenate([sun, sun[::-1], sun]), np.concatenate([obs, obs, obs[::-1]])
    wl = np.arange(400.0, 801.0, 50.0)
    e = np.ones((len(sun), len(wl)))
    kw = dict(
        mode="path",
        resolution_px=16,
        samples_per_pixel=16,
        seed=9,
        keep_images_for=[2],
        solar_disk=solar_disk,  # the Sun a sphere moved between epochs (the scene updated)
    )
    monkeypatch.setattr(sampling, "MAX_LANES", 16 * 16 * 16 * 5 // 12)
    monkeypatch.setattr(path, "FREEZE_MIN_LAUNCHES", 1)  # frozen however short the run
    frozen = render_intensity(target, sun, obs, e, wl, **kw)
    monkeypatch.delattr(dr, "freeze")
    traced = render_intensity(target, sun, obs, e, wl, **kw)
    np.testing.assert_allclose(
        frozen.intensity_W_sr_nm, traced.intensity_W_sr_nm, rtol=FLOAT32_ROUNDING
    )
    np.testing.assert_allclose(
        frozen.images[2].radiance_W_m2_sr_nm,
        traced.images[2].radiance_W_m2_sr_nm,
        rtol=FLOAT32_ROUNDING,
        atol=FLOAT32_ROUNDING * float(np.max(traced.images[2].radiance_W_m2_sr_nm)),
    )


def test_freeze_env_zero_traces_every_launch(monkeypatch):
    # SPECLIGHT_PATH_FREEZE=0 is the way around a Dr.Jit whose frozen functions fail: no
    # launch may then be frozen, and the result is the traced one.
    import drjit as dr

    import speclight.render.path as path
    import speclight.render.path_sampling as sampling

    if not hasattr(dr, "freeze"):
        pytest.skip("this Dr.Jit has no frozen functions")
    calls = []
    real = dr.freeze

    def spy(f):  # type: ignore[no-untyped-def]
        calls.append(f)
        return real(f)

    target = _coated_box_wing()
    sun, obs = _box_wing_geometry()
    wl = np.arange(400.0, 801.0, 100.0)
    e = np.ones((len(sun), len(wl)))
    kw = dict(mode="path", resolution_px=8, samples_per_pixel=4, seed=3)
    monkeypatch.setattr(path, "FREEZE_MIN_LAUNCHES", 1)
    monkeypatch.setattr(dr, "freeze", spy)
    monkeypatch.setenv(sampling.FREEZE_ENV, "0")
    off = render_intensity(target, sun, obs, e, wl, **kw)
    assert calls == []
    monkeypatch.delenv(sampling.FREEZE_ENV)
    on = render_intensity(target, sun, obs, e, wl, **kw)
    assert len(calls) == 1
    np.testing.assert_allclose(off.intensity_W_sr_nm, on.intensity_W_sr_nm, rtol=FLOAT32_ROUNDING)
