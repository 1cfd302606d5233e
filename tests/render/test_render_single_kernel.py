"""The single mode's Dr.Jit kernel (speclight.render.single_kernel) against its numpy path.

The numpy path (pixel rays in numpy, Mitsuba's intersections copied back, weights in numpy,
``np.bincount`` per epoch) is the independent implementation here: the kernel generates the
same float32 rays, shades in float64 and sums in fixed point, so its channel sums must equal
numpy's to the rounding stated in each test. The per-model weights are held together by
the BSDF contract test (test_bsdf_contract.py); closed forms (Lambert's sphere, plates) run
through the kernel in test_render_single_closed_forms.py with the vectorised caster.
"""

from __future__ import annotations

import numpy as np
import pytest

from speclight.render import available_variants, single_kernel
from speclight.render import single as single_module
from speclight.render.material_channels import ChannelLayout
from speclight.render.raycast import MitsubaCaster
from speclight.render.single import geometric_weights
from speclight.target import box_wing, cube, material_from_spec, sphere

VARIANT = next(
    (v for v in available_variants() if v.startswith(("llvm_", "cuda_")) and v.endswith("_rgb")),
    None,
)
pytestmark = pytest.mark.skipif(VARIANT is None, reason="the kernel needs a vectorised variant")
RESOLUTION_PX = 48
EPS = np.finfo(float).eps


def _materials() -> dict:
    """One material per kernel model family: coat (rough and smooth: a glint), lab table
    with its extension, analytic fit, microfacet, Lambert."""
    spec = {
        "bus": {"bsdf": "plastic", "roughness": 0.3, "reflectance": {"dielectric": "Kapton"},
                "diffuse_reflectance": 0.5},
        "wing_+y": {"bsdf": "plastic", "reflectance": {"dielectric": "SiO2"},
                    "diffuse_reflectance": 0.06},
        "wing_-y": {"bsdf": "measured", "brdf_table": "starlink_v1p5_solar_array_532nm",
                    "extension": "abg"},
        "antenna": {"bsdf": "phong", "coefficients": {"kd": 0.2, "ks": 0.5, "n": 30.0}},
    }  # fmt: skip
    return {part: material_from_spec(part.replace("+", "p"), s) for part, s in spec.items()}


def _geometry(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Random Sun and observer directions, with a backscatter and a glint epoch."""
    rng = np.random.default_rng(seed)
    sun = rng.normal(size=(n, 3))
    obs = rng.normal(size=(n, 3))
    obs[0] = sun[0]  # phase angle 0
    sun[1], obs[1] = [1.0, 0.3, 0.2], [1.0, -0.3, -0.2]  # the wings' mirror pair (normal x)
    unit = np.linalg.norm
    return sun / unit(sun, axis=1, keepdims=True), obs / unit(obs, axis=1, keepdims=True)


def _numpy_path(monkeypatch: pytest.MonkeyPatch, *args, **kw):
    """geometric_weights with the kernel switched off (every batch through numpy)."""
    with monkeypatch.context() as m:
        m.setattr(single_module, "kernel_supported", lambda *a: False)
        return geometric_weights(*args, **kw)[0]


def _magnitudes(monkeypatch: pytest.MonkeyPatch, target, sun, obs, caster, **kw) -> np.ndarray:
    """Sum of |weight| over the pixels per epoch and channel [m² sr-1] (numpy path, from
    every epoch's kept pixels): what a mixed-sign channel's rounding scales with."""
    with monkeypatch.context() as m:
        m.setattr(single_module, "kernel_supported", lambda *a: False)
        keep = range(len(sun))
        w, kept, _, _ = geometric_weights(target, sun, obs, caster, RESOLUTION_PX, keep=keep, **kw)
    out = np.zeros_like(w)
    for e, pix in kept.items():
        np.add.at(out[e], pix.channel, np.abs(pix.weight))
    return out


def _tolerance(magnitude: np.ndarray) -> np.ndarray:
    """What the two paths may differ by per channel [m² sr-1], given its sum of |weight|
    (``magnitude``): the kernel's fixed-point rounding (single_kernel module doc: at most
    2^-bits of the sum's largest |weight| per pixel), the models' float64 rounding on either
    side (16 ulp, test_bsdf_contract.KERNEL_ULPS) and numpy's sequential float64 sum over
    the pixels (at most one ulp of the partial sum per pixel added)."""
    pixels = RESOLUTION_PX**2
    return (pixels * 2.0 ** -single_kernel.fraction_bits(pixels) + (16 + pixels) * EPS) * magnitude


def test_kernel_channel_sums_equal_the_numpy_path(monkeypatch):
    target = box_wing(_materials())
    caster = MitsubaCaster(target, VARIANT)
    sun, obs = _geometry(12, seed=4)
    w_kernel, _, _, layout = geometric_weights(target, sun, obs, caster, RESOLUTION_PX)
    w_numpy = _numpy_path(monkeypatch, target, sun, obs, caster, RESOLUTION_PX)
    kernel = single_kernel.SingleKernel(target, caster, layout, RESOLUTION_PX)
    assert kernel.channel_sums(sun, obs) is not None  # the kernel's sums, not numpy's
    assert layout.n_channels == 4 + 2 * 33**2 + 1  # main, two coats' bases, the extension
    for k in range(4):  # every material seen and lit (main channel or block)
        start = layout.block.get(k, k)
        assert np.any(w_numpy[:, k] > 0) or np.any(w_numpy[:, start : start + 33**2] > 0)
    assert w_numpy[1, 1] > 0  # the smooth coat's glint
    assert np.all(np.abs(w_kernel - w_numpy) <= _tolerance(np.abs(w_numpy)))


def test_kernel_on_a_sphere_with_roughness_derivatives(monkeypatch):
    # Spheres are Mitsuba shapes (no triangles); the derivative channels of the gradient
    # render (speclight.render.single_gradient) are summed in the kernel too.
    m = material_from_spec("m", {"bsdf": "ggx", "roughness": 0.2, "reflectance": 0.7})
    target = sphere(1.0, m)
    caster = MitsubaCaster(target, VARIANT)
    sun, obs = _geometry(6, seed=9)
    layout = ChannelLayout(target, [0])
    w_kernel = geometric_weights(target, sun, obs, caster, RESOLUTION_PX, layout=layout)[0]
    w_numpy = _numpy_path(monkeypatch, target, sun, obs, caster, RESOLUTION_PX, layout=layout)
    kernel = single_kernel.SingleKernel(target, caster, layout, RESOLUTION_PX)
    assert kernel.channel_sums(sun, obs) is not None  # the kernel's sums, not numpy's
    assert np.all(w_numpy[:, 0] > 0) and np.any(w_numpy[:, 1] != 0)
    magnitude = _magnitudes(monkeypatch, target, sun, obs, caster, layout=layout)
    assert np.all(np.abs(w_kernel - w_numpy) <= _tolerance(magnitude))


def test_kernel_sums_do_not_depend_on_the_thread_count():
    # Integer (fixed-point) atomics are exact: the sums are the same bits however the
    # lanes are scheduled (float atomics would sum in a schedule-dependent order).
    import drjit as dr

    target = box_wing(_materials())
    caster = MitsubaCaster(target, VARIANT)
    kernel = single_kernel.SingleKernel(target, caster, ChannelLayout(target), RESOLUTION_PX)
    sun, obs = _geometry(8, seed=2)
    threads = dr.thread_count()
    try:
        many = kernel.channel_sums(sun, obs)
        dr.set_thread_count(1)
        one = kernel.channel_sums(sun, obs)
    finally:
        dr.set_thread_count(threads)
    assert many is not None and one is not None
    assert np.array_equal(many, one)


def test_weights_not_finite_take_the_numpy_path(monkeypatch):
    # An infinite weight has no fixed-point scale: the kernel refuses the batch and numpy
    # renders it, so the result is the numpy path's (infinite) to the bit.
    from speclight.render.bsdfs.bsdf_lambertian import LambertianBsdf

    target = sphere(1.0, material_from_spec("m", {"bsdf": "lambertian", "reflectance": 0.5}))
    caster = MitsubaCaster(target, VARIANT)
    sun, obs = _geometry(3, seed=1)
    monkeypatch.setattr(LambertianBsdf, "main_weight", lambda self, cos_i, *a, **k: cos_i + np.inf)
    kernel = single_kernel.SingleKernel(target, caster, ChannelLayout(target), RESOLUTION_PX)
    assert kernel.channel_sums(sun, obs) is None
    w = geometric_weights(target, sun, obs, caster, RESOLUTION_PX)[0]
    assert np.isinf(w).any()
    assert np.array_equal(w, _numpy_path(monkeypatch, target, sun, obs, caster, RESOLUTION_PX))


def test_scale_exponents_follow_the_float64_exponent():
    # IEEE 754 binary64: the high word holds the sign, 11 exponent bits (bias 1023) and 20
    # mantissa bits, so |w| < 2^(e - 1022) for biased exponent e (subnormals: e = 0); the
    # all-ones exponent is infinity or NaN.
    bits = 70
    peaks = np.array([1.0, 1.5e-12, 3e300, 5e-324, 0.0, np.inf, np.nan])
    high = (peaks.view(np.uint64) >> np.uint64(32)).astype(np.uint32)
    assert single_kernel.scale_exponents(high, bits) is None
    k = single_kernel.scale_exponents(high[:5], bits)
    assert k is not None
    scaled = np.ldexp(peaks[:5], k)
    assert np.all(scaled < 2.0**bits) and np.all(scaled[:3] >= 2.0 ** (bits - 1))  # normal
    assert single_kernel.fraction_bits(256**2) == 94 - 18  # 4 x 2^16 high words < 2^62


def test_tiny_weights_keep_their_relative_precision(monkeypatch):
    # A glossy Beckmann cube lit and seen far from its faces' mirror directions, at phase
    # 0 as a laser lights it: D = exp(-tan^2 / alpha^2) / ... makes every weight tiny
    # (1e-11 to 1e-103 sr-1), nearly dark epochs. Each (epoch, channel) sum keeps float64's
    # relative precision (the fixed point scales with its largest weight): it equals the
    # numpy path to float64 rounding, relative to itself, never 0.
    faces = ("+x", "-x", "+y", "-y", "+z", "-z")
    spec = {"bsdf": "beckmann", "roughness": 0.15}
    target = cube(1.0, {f: material_from_spec(f"m{i}", {**spec, "reflectance": 0.1 * (i + 1)})
                        for i, f in enumerate(faces)})  # fmt: skip
    caster = MitsubaCaster(target, VARIANT)
    axes = np.array([[1.0, 1.0, 1.0], [1.0, 0.6, 0.5], [-0.7, 1.0, 0.8], [0.5, -0.6, -1.0]])
    both = axes / np.linalg.norm(axes, axis=1, keepdims=True)  # Sun = observer: phase 0
    w_kernel, _, _, layout = geometric_weights(target, both, both, caster, RESOLUTION_PX)
    w_numpy = _numpy_path(monkeypatch, target, both, both, caster, RESOLUTION_PX)
    kernel = single_kernel.SingleKernel(target, caster, layout, RESOLUTION_PX)
    assert kernel.channel_sums(both, both) is not None  # the kernel's sums, not numpy's
    seen = w_numpy > 0
    assert seen.sum(axis=1).tolist() == [3, 3, 3, 3]  # three faces toward each direction
    assert w_numpy[seen].max() < 1e-10 and w_numpy[seen].min() < 1e-100
    assert np.all(w_kernel[~seen] == 0.0)
    assert np.all(np.abs(w_kernel - w_numpy) <= _tolerance(w_numpy))


def test_materials_sharing_a_weight_function_are_summed_apart(monkeypatch):
    # Materials whose weights are one function of the cosines (Lambert at any albedo; one
    # microfacet lobe under different Fresnel terms) are evaluated once in the kernel
    # (MaterialBsdf.kernel_key) but still summed into their own channels.
    spec = {
        "+x": {"bsdf": "lambertian", "reflectance": 0.2},
        "-x": {"bsdf": "lambertian", "reflectance": 0.9},
        "+y": {"bsdf": "beckmann", "roughness": 0.2, "reflectance": {"conductor": "Al"}},
        "-y": {"bsdf": "beckmann", "roughness": 0.2, "reflectance": 0.5},
        "*": {"bsdf": "lambertian", "reflectance": 0.5},
    }
    target = cube(1.0, {p: material_from_spec(p.replace("+", "p"), s) for p, s in spec.items()})
    caster = MitsubaCaster(target, VARIANT)
    sun, obs = _geometry(10, seed=6)
    w_kernel, _, _, layout = geometric_weights(target, sun, obs, caster, RESOLUTION_PX)
    w_numpy = _numpy_path(monkeypatch, target, sun, obs, caster, RESOLUTION_PX)
    assert len(single_kernel._groups(layout, main=True)) == 2  # Lambert, the one lobe
    assert np.all(np.any(w_numpy > 0, axis=0))  # every material's channel
    assert np.all(np.abs(w_kernel - w_numpy) <= _tolerance(np.abs(w_numpy)))


def test_roughness_derivatives_of_several_weight_groups(monkeypatch):
    # Lanes of different weight groups (two lobes, Lambert) each evaluate their own group's
    # weight and derivative in the kernel (one dr.switch): the derivative channels of both
    # lobes equal the numpy path's, the Lambert lanes add none.
    spec = {
        "+x": {"bsdf": "ggx", "roughness": 0.2, "reflectance": 0.7},
        "-x": {"bsdf": "beckmann", "roughness": 0.4, "reflectance": 0.5},
        "*": {"bsdf": "lambertian", "reflectance": 0.5},
    }
    names = {"+x": "px", "-x": "mx", "*": "rest"}
    target = cube(1.0, {p: material_from_spec(names[p], s) for p, s in spec.items()})
    caster = MitsubaCaster(target, VARIANT)
    sun, obs = _geometry(12, seed=3)
    layout = ChannelLayout(target, [0, 1])
    assert len(single_kernel._groups(layout, main=True)) == 3
    w_kernel = geometric_weights(target, sun, obs, caster, RESOLUTION_PX, layout=layout)[0]
    w_numpy = _numpy_path(monkeypatch, target, sun, obs, caster, RESOLUTION_PX, layout=layout)
    assert all(np.any(w_numpy[:, layout.grad[k]] != 0) for k in (0, 1))
    magnitude = _magnitudes(monkeypatch, target, sun, obs, caster, layout=layout)
    assert np.all(np.abs(w_kernel - w_numpy) <= _tolerance(magnitude))
