"""Path mode's sampling of the analytic models: unbiased, whatever the lobe.

Reference: the directional albedo a(theta_i) = int f cos(theta_o) d omega (the quadrature
of speclight.target.brdf_fit.directional_albedo, accurate to 2e-5 on these lobes). The
weights ``f cos / pdf`` of directions drawn by the BSDF's ``sample`` average to it if and
only if the sampled density is the pdf the BSDF reports (Pharr, Jakob & Humphreys, PBRT 4th
ed., sec. 2.1); the path tracer's multiple bounces rely on that. The single-vs-path check of
every model's value is the contract test's (tests/render/test_bsdf_contract.py).
"""

from __future__ import annotations

import numpy as np
import pytest

from speclight.render import available_variants
from speclight.target.brdf_fit.directional_albedo import directional_albedo
from speclight.target.brdf_fit.form_coefficients import evaluate
from speclight.target.bsdf_models import BSDF_MODELS

VARIANT = next(
    (v for v in ("llvm_ad_spectral", "cuda_ad_spectral") if v in available_variants()), None
)
SAMPLES = 400_000
#: z-test bound on the mean weight (fixed seed: a pass is reproducible), plus the
#: quadrature's accuracy.
Z_MAX, QUADRATURE = 4.0, 2e-5
CASES = [
    (e["bsdf"], e["coefficients"])
    for name in ("phong", "abg", "binomial", "microfacet")
    for e in BSDF_MODELS[name].examples
    if "reflectance" not in e
]


@pytest.mark.skipif(VARIANT is None, reason="needs a vectorised spectral Mitsuba variant")
@pytest.mark.parametrize(("model", "coefficients"), CASES, ids=[c[0] for c in CASES])
def test_sampled_weights_average_to_the_albedo(model, coefficients):
    import drjit as dr

    from speclight.render.bsdfs.path_analytic import analytic_bsdf
    from speclight.render.variant import activate

    mi = activate(VARIANT)
    bsdf = analytic_bsdf(mi, model, dict(coefficients), np.array([400.0, 800.0]), np.ones(2))
    rng = np.random.default_rng(3)
    for theta_deg in (10.0, 60.0):
        t = np.radians(theta_deg)
        si = dr.zeros(mi.SurfaceInteraction3f, SAMPLES)
        si.wi = mi.Vector3f(float(np.sin(t)), 0.0, float(np.cos(t)))
        si.wavelengths = mi.Spectrum(550.0)
        u = rng.random((3, SAMPLES)).astype(np.float32)
        _, weight = bsdf.sample(mi.BSDFContext(), si, mi.Float(u[0]), mi.Point2f(u[1], u[2]))
        w = np.array(weight[0], dtype=float)
        want = directional_albedo(lambda *c: evaluate(model, coefficients, *c), t)
        error = Z_MAX * w.std() / np.sqrt(SAMPLES) + QUADRATURE
        assert abs(w.mean() - want) <= error, (theta_deg, w.mean(), want, error)
