"""The analytic forms give lumos-sat's BRDF values for the same coefficients.

Oracle: lumos-sat 1.0.9 (``lumos.brdf.library``: ``PHONG``, ``ABG``, ``BINOMIAL``), the
package that fitted these forms to the Starlink lab tables (Fankhauser, Askari & Tyson 2023,
doi:10.48550/arXiv.2305.11123). It evaluates them from the light, normal and view vectors;
speclight from the shading cosines (speclight.target.brdf_fit.analytic_forms): the same
values at random geometries mean the same conventions (which vector is which, the
projected-vector distance, the binomial's indices). Installed by scripts/setup.sh --dev.
"""

from __future__ import annotations

import numpy as np
import pytest

from speclight.target.brdf_fit.directional_albedo import shading_cosines
from speclight.target.brdf_fit.form_coefficients import evaluate

library = pytest.importorskip("lumos.brdf.library")

#: float64 rounding through two different formulas (vectors vs cosines), relative. Near a
#: peak lumos-sat's |beta - beta_0| is a difference of nearly equal vectors (relative error
#: ~1e-16 / x for x ~ 1e-4..1e-3 within 2 deg of the mirror), raised to the power g; the
#: binomial's 10^(sum of terms) multiplies the rounding of log10 f by ln 10 |log10 f|.
#: Measured: 5e-11 (ABg), 3e-13 (binomial), 3e-14 (Phong).
ROUNDING = 1e-9


def _geometries(count: int) -> tuple[np.ndarray, np.ndarray]:
    """Light and view unit vectors above the surface z > 0, uniform in solid angle, with a
    tenth of them within 2 deg of the mirror direction (the peaks)."""
    rng = np.random.default_rng(24)

    def hemisphere(n: int) -> np.ndarray:
        cos = rng.uniform(0.02, 1.0, n)
        phi = rng.uniform(0.0, 2 * np.pi, n)
        sin = np.sqrt(1 - cos**2)
        return np.stack([sin * np.cos(phi), sin * np.sin(phi), cos], axis=1)

    s = hemisphere(count)
    o = hemisphere(count)
    near = slice(0, count // 10)
    mirror = s[near] * [-1.0, -1.0, 1.0]
    o[near] = mirror + rng.normal(0.0, np.radians(1.0), mirror.shape)
    o[near, 2] = np.abs(o[near, 2]) + 0.01
    o /= np.linalg.norm(o, axis=1)[:, None]
    return s, o


# (lumos-sat factory, its arguments, speclight's model and coefficients)
CASES = [
    ("PHONG", (0.2, 0.5, 30.0), "phong", {"kd": 0.2, "ks": 0.5, "n": 30.0}),
    # Kandula et al. 2025's "chassis offset" (starlink_gen2_surfaces.txt)
    ("PHONG", (0.056, 0.0, 0.194), "phong", {"kd": 0.056, "ks": 0.0, "n": 0.194}),
    # Kandula et al. 2025's ABg fits (boom; bare aluminium chassis)
    ("ABG", (9.737e-5, 8.448e-6, 2.686), "abg", {"a": 9.737e-5, "b": 8.448e-6, "g": 2.686}),
    ("ABG", (0.01999, 2.285e-6, 2.264), "abg", {"a": 0.01999, "b": 2.285e-6, "g": 2.264}),
]


@pytest.mark.parametrize(("factory", "args", "model", "coefficients"), CASES)
def test_phong_and_abg_match_lumos(factory, args, model, coefficients):
    s, o = _geometries(4000)
    want = getattr(library, factory)(*args)(tuple(s.T), (0.0, 0.0, 1.0), tuple(o.T))
    got = evaluate(model, coefficients, *shading_cosines(s, o))
    np.testing.assert_allclose(got, want, rtol=ROUNDING, atol=0.0)


@pytest.mark.parametrize("rows", [1, 2])
def test_binomial_matches_lumos(rows):
    # lumos-sat's chassis shape (m = 2, l1 = -5, l2 = 5, d = 3) with coefficients of the size
    # its fits give; two rows (powers of V) exercise the V^k terms too
    rng = np.random.default_rng(rows)
    b = rng.normal(0.0, 1.0, (rows, 2))
    c = rng.normal(0.0, 0.3, (rows, 10))
    s, o = _geometries(4000)
    lumos = library.BINOMIAL(b, c, 3.0, -5)
    want = lumos(tuple(s.T), (0.0, 0.0, 1.0), tuple(o.T))
    coefficients = {"b": b.tolist(), "c": c.tolist(), "d": 3.0, "l1": -5}
    got = evaluate("binomial", coefficients, *shading_cosines(s, o))
    np.testing.assert_allclose(got, want, rtol=ROUNDING, atol=0.0)
