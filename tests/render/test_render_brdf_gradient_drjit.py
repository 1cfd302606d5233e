"""The analytic roughness derivatives against Dr.Jit's automatic differentiation of Mitsuba.

Reference: Mitsuba 3's own ``roughconductor`` plugin (``material: none``, so F = 1), whose
``eval(si.wi = observer, wo = Sun)`` is ``D G / (4 cos_observer)`` with the same Beckmann
(Walter et al. 2007 rational Smith approximation) and GGX terms, differentiated in forward
mode by Dr.Jit (``llvm_ad_rgb``) with respect to its ``alpha`` parameter: an independent
implementation and an independent derivative (no finite differences). Mitsuba evaluates in
float32, hence the tolerance (1e-4 of the largest value, ~1000 float32 steps).
"""

import numpy as np
import pytest

from speclight.render.brdf_gradient import microfacet_weight_dalpha
from speclight.render.variant import available_variants
from speclight.target.microfacet_terms import microfacet_weight

pytestmark = pytest.mark.skipif(
    "llvm_ad_rgb" not in available_variants(), reason="needs Mitsuba's llvm_ad_rgb (libLLVM)"
)


def _directions(rng: np.random.Generator, n: int) -> np.ndarray:
    """Unit vectors in the upper hemisphere, cos theta in [0.05, 1]."""
    cos_t = rng.uniform(0.05, 1.0, n)
    phi = rng.uniform(0.0, 2.0 * np.pi, n)
    sin_t = np.sqrt(1.0 - cos_t**2)
    return np.stack([sin_t * np.cos(phi), sin_t * np.sin(phi), cos_t], axis=1)


@pytest.mark.parametrize("kind", ["beckmann", "ggx"])
@pytest.mark.parametrize("alpha", [0.05, 0.2, 0.6])
def test_roughness_derivative_equals_drjit_forward_mode_of_mitsuba(kind, alpha):
    from speclight.render.variant import activate

    mi = activate("llvm_ad_rgb")
    import drjit as dr

    rng = np.random.default_rng(7)
    n = 4000
    obs, sun = _directions(rng, n), _directions(rng, n)
    bsdf = mi.load_dict(
        {"type": "roughconductor", "distribution": kind, "alpha": alpha, "material": "none"}
    )
    params = mi.traverse(bsdf)
    dr.enable_grad(params["alpha.value"])
    params.update()
    si = dr.zeros(mi.SurfaceInteraction3f, n)
    si.sh_frame = mi.Frame3f(mi.Vector3f(0.0, 0.0, 1.0))
    si.n = mi.Normal3f(0.0, 0.0, 1.0)
    si.wi = mi.Vector3f(obs.T)
    value = bsdf.eval(mi.BSDFContext(), si, mi.Vector3f(sun.T))
    dr.forward(params["alpha.value"])
    theirs = np.array(value)[0]
    d_theirs = np.array(dr.grad(value))[0]

    half = (sun + obs) / np.linalg.norm(sun + obs, axis=1, keepdims=True)
    ours = microfacet_weight(sun[:, 2], obs[:, 2], half[:, 2], alpha, kind)
    d_ours = microfacet_weight_dalpha(sun[:, 2], obs[:, 2], half[:, 2], alpha, kind)
    np.testing.assert_allclose(theirs, ours, rtol=1e-4, atol=1e-4 * ours.max())
    np.testing.assert_allclose(d_theirs, d_ours, rtol=1e-4, atol=1e-4 * np.abs(d_ours).max())
    assert np.abs(d_ours).max() > 0.1  # the derivative is not trivially zero here
