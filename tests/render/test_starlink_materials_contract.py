"""The materials the built-in Starlink examples fly, through the BSDF contract's checks
(issue 24, items 4 and 5).

tests/render/test_bsdf_contract.py holds every registered model to reciprocity and the white
furnace with the registry's own example coefficients; the Starlink examples use other ones
(the v1.5 lab tables with their default fitted extension, the V2 mini's fits of the
second-generation tables and Kandula et al. 2025's published models). Each distinct
material of the two examples is held here to the same checks, with the same harness:

1. Helmholtz reciprocity (PBRT 4th ed., sec. 4.3.1), f(s -> o) = f(o -> s), at random pairs
   and mirror pairs, to float64 rounding through the model;
2. the white furnace: the directional albedo at 0, 30, 60 and 80 deg incidence is at most 1
   within the quadrature's own error estimate.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_bsdf_contract import INCIDENCE_DEG, _albedo_with_error, _brdf, _directions

from speclight.scenario import load_example
from speclight.simulation.reflection import build_target

EXAMPLES = ("starlink-v1.5", "starlink-v2-mini")


def _materials() -> list:
    out, seen = [], set()
    for name in EXAMPLES:
        for part in build_target(load_example(name)).parts:
            m = part.material
            key = (m.bsdf, repr(getattr(m, "coefficients", None)), repr(m.brdf_table))
            if key not in seen:
                seen.add(key)
                out.append(pytest.param(m, id=f"{name}-{part.name}"))
    return out


MATERIALS = _materials()


def test_every_starlink_part_is_checked():
    # v1.5: chassis table (bus_nadir, bus) and array table; V2 mini: 8 parts, the two dish
    # parts share one fit
    assert len(MATERIALS) == 2 + 7


@pytest.mark.parametrize("material", MATERIALS)
def test_starlink_material_is_reciprocal(material):
    rng = np.random.default_rng(11)
    s = np.concatenate([_directions(rng, 300), _directions(rng, 60)])
    o = np.concatenate([_directions(rng, 300), s[300:] * [-1.0, -1.0, 1.0]])  # mirror pairs
    forward, backward = _brdf(material, s, o), _brdf(material, o, s)
    assert np.any(forward[300:] > 0), "the mirror pairs must see the lobe"
    # the same formulas on cosines that differ by rounding (test_bsdf_contract.py: measured
    # 2e-16 for the analytic models, 7e-14 for a lab table)
    assert np.all(np.abs(forward - backward) <= 1e-12 * np.maximum(forward, backward))


@pytest.mark.parametrize("material", MATERIALS)
def test_starlink_material_reflects_at_most_what_it_receives(material):
    for theta in np.radians(INCIDENCE_DEG):
        albedo, error = _albedo_with_error(material, theta)
        assert error < 2e-2, "the quadrature does not resolve the model"
        assert np.all(albedo <= 1.0 + error + 1e-12), (np.degrees(theta), albedo, error)
