"""Path mode's polarisation (Mitsuba ``*_spectral_polarized``) against the single mode.

The single mode's Stokes vectors are checked against closed forms in
``test_render_polarization.py``; here the path tracer, whose Mueller matrices are Mitsuba's
own (its ``roughconductor`` and ``diffuse`` in a polarised variant), must agree with it
within the Monte Carlo standard error on convex targets (one bounce only), in the same sky
frame (so Mitsuba's implicit Stokes basis and its rotation to north are checked too).
"""

from __future__ import annotations

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.render import available_variants, render_intensity
from speclight.render.session import RenderSession
from speclight.target import Material, Reflectance, plate, sphere

pytestmark = pytest.mark.skipif(
    not any(
        v.endswith("_spectral_polarized") and v.startswith(("llvm_", "cuda_"))
        for v in available_variants()
    ),
    reason="polarised path mode needs a vectorised *_spectral_polarized Mitsuba variant",
)
#: z-test bound (as test_render_path_coat.py): 4 standard errors of the 8-pass estimate.
Z_MAX = 4.0
#: Narrow bins: the path mode averages n, k over each bin, the single mode takes the centre.
WL = np.array([499.0, 500.0, 501.0])
POLE = np.array([[0.0, 0.3, 1.0]]) / np.linalg.norm([0.0, 0.3, 1.0])


def _both(target, sun, obs, spp=64, res=32):
    sun, obs = np.atleast_2d(sun), np.atleast_2d(obs)
    kw = dict(resolution_px=res, polarization=True, pole_body=POLE)
    single = render_intensity(target, sun, obs, np.ones(3), WL, variant="numpy", **kw)
    path = render_intensity(
        target, sun, obs, np.ones(3), WL, mode="path", samples_per_pixel=spp, seed=3, **kw
    )
    return single, path


def _fractions(r):
    return r.stokes_W_sr_nm / r.intensity_W_sr_nm[..., None]


@pytest.mark.parametrize(
    "material",
    [
        Material("gold", "ggx", Reflectance.conductor("Au"), roughness=0.3),
        Material("glass", "beckmann", Reflectance.dielectric("SiO2"), roughness=0.2),
    ],
    ids=["rough conductor", "rough dielectric"],
)
def test_rough_surfaces_agree_with_single_mode(material: Material) -> None:
    single, path = _both(sphere(1.0, material), [0.2, 0.9, 0.3], [1.0, 0.0, 0.2])
    assert path.variant.endswith("_spectral_polarized")
    st, sd = path.stokes_W_sr_nm, path.stokes_std_W_sr_nm
    i_single = single.intensity_W_sr_nm
    # Q/I, U/I of the single mode times the path's intensity (the shared shading model's
    # intensity difference is the non-polarised tests' business), compared within the
    # standard error of Q, U
    expect = _fractions(single)[..., :2] * path.intensity_W_sr_nm[..., None]
    z = (st[..., :2] - expect) / np.hypot(sd[..., :2], 1e-3 * np.abs(expect))
    assert np.all(np.abs(z) < Z_MAX), z
    assert np.max(np.abs(_fractions(single)[..., :2])) > 0.05  # a polarising case
    # one bounce on microfacets whose normal is the half vector: every sample has the same
    # Q/I, so the fractions agree beyond the noise (bins 1 nm wide: n, k vary < 1e-4)
    np.testing.assert_allclose(_fractions(path)[..., :2], _fractions(single)[..., :2], atol=1e-4)
    assert np.all(np.abs(st[..., 2]) <= Z_MAX * sd[..., 2] + 1e-12 * i_single)  # V = 0


def test_lambertian_sphere_is_unpolarised_in_path_mode() -> None:
    grey = Material("grey", "lambertian", Reflectance.constant(0.5))
    _, path = _both(sphere(1.0, grey), [0.2, 0.9, 0.3], [1.0, 0.0, 0.2])
    assert np.all(path.intensity_W_sr_nm > 0)
    st, sd = path.stokes_W_sr_nm, path.stokes_std_W_sr_nm
    assert np.all(np.abs(st) <= Z_MAX * sd + 1e-12)


def test_diffuse_and_conductor_target_renders_non_black() -> None:
    # the users' trap: polarised variants rendering black. A plate of two materials is not
    # available as a builtin; a diffuse sphere and a conductor plate render separately.
    alu = Material("alu", "beckmann", Reflectance.conductor("Al"), roughness=0.2)
    grey = Material("grey", "lambertian", Reflectance.constant(0.3))
    for target in (plate(1.0, 1.0, alu), sphere(0.5, grey)):
        sun = np.array([0.3, 0.0, 1.0]) / np.linalg.norm([0.3, 0.0, 1.0])
        _, path = _both(target, sun, [-0.2, 0.1, 1.0], spp=16, res=16)
        assert np.all(path.intensity_W_sr_nm > 0)


def test_path_refuses_what_it_cannot_polarise() -> None:
    base = Reflectance.constant(0.5)
    plastic = Material("coat", "plastic", Reflectance.dielectric("SiO2"), diffuse_reflectance=base)
    with pytest.raises(InputError, match=r"'coat'.*render.mode 'path'"):
        RenderSession.create("path", None, [plastic], polarization=True)
    with pytest.raises(InputError, match="_spectral_polarized"):
        RenderSession.create("path", "llvm_ad_spectral", [], polarization=True)
    table = Material(
        "panel", "measured", Reflectance.constant(1.0), brdf_table="starlink_v1p5_chassis_532nm"
    )
    with pytest.raises(InputError, match="panel"):
        RenderSession.create("path", None, [table], polarization=True)
    grey = Material("grey", "lambertian", Reflectance.constant(0.5))
    plain = RenderSession.create("path", None, [grey])  # made without polarization
    with pytest.raises(InputError, match="_spectral_polarized"):
        render_intensity(
            sphere(1.0, grey), [[0, 0, 1.0]], [[1.0, 0, 0]], np.ones(3), WL, session=plain,
            polarization=True, pole_body=POLE,
        )  # fmt: skip


def test_dielectric_microfacet_without_absorption_renders_in_path_mode() -> None:
    # k = 0 everywhere (fused silica): Mitsuba refuses an all-zero irregular spectrum, the
    # scene gives it the constant 0 (this failed before, polarised or not)
    glass = Material("glass", "ggx", Reflectance.dielectric("SiO2"), roughness=0.2)
    r = render_intensity(
        sphere(1.0, glass), [[0.2, 0.9, 0.3]], [[1.0, 0.0, 0.2]], np.ones(3), WL,
        mode="path", resolution_px=16, samples_per_pixel=8, variant="llvm_ad_spectral",
    )  # fmt: skip
    assert np.all(r.intensity_W_sr_nm > 0)
