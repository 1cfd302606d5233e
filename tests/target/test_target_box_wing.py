"""The built-in box-wing as docs/scenario.md ("The box-wing") describes it, and its dish
left out with ``dish: false``."""

import numpy as np
import pytest
import yaml

from speclight.errors import InputError
from speclight.scenario import parse_scenario
from speclight.scenario.builtin_examples import example_text
from speclight.simulation.reflection import build_target
from speclight.target import Material, Reflectance, box_wing

WHITE = Material("white", "lambertian", Reflectance.constant(1.0))
#: Coordinates are written from sums of the sizes: exact to a few ulps of 10 m [m].
COORD_TOL_M = 1e-12


def _normals(part) -> np.ndarray:
    v, f = part.vertices_m, part.faces
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def test_the_documented_geometry():
    bus, span, width, gap, radius, depth = (1.2, 0.8, 1.6), 3.5, 1.1, 0.25, 0.45, 0.12
    target = box_wing(WHITE, bus, span, width, gap, radius, depth)
    parts = {p.name: p for p in target.parts}
    assert list(parts) == ["bus", "wing_+y", "wing_-y", "antenna"]
    v = parts["bus"].vertices_m
    np.testing.assert_allclose(v.min(axis=0), -np.array(bus) / 2, atol=COORD_TOL_M)
    np.testing.assert_allclose(v.max(axis=0), np.array(bus) / 2, atol=COORD_TOL_M)
    for name, sign in (("wing_+y", 1.0), ("wing_-y", -1.0)):
        w = parts[name].vertices_m
        np.testing.assert_allclose(w[:, 0], 0.0, atol=COORD_TOL_M)  # in the y-z plane
        y = np.sort(sign * w[:, 1])
        np.testing.assert_allclose(
            [y.min(), y.max()], [bus[1] / 2 + gap, bus[1] / 2 + gap + span], atol=COORD_TOL_M
        )
        np.testing.assert_allclose(np.abs(w[:, 2]), width / 2, atol=COORD_TOL_M)
        # the wing normal as built is +x for both wings (docs; articulation normal [1, 0, 0])
        np.testing.assert_allclose(_normals(parts[name]), [[1.0, 0.0, 0.0]] * 2, atol=1e-15)
    d = parts["antenna"].vertices_m
    rho = np.hypot(d[:, 0], d[:, 1])
    apex_z = -bus[2] / 2 - 1e-3
    assert rho.max() == pytest.approx(radius, abs=COORD_TOL_M)
    # paraboloid z = z0 + depth (1 - (rho / R)^2), apex 1 mm below the bus, opening to -z
    z0 = apex_z - depth
    np.testing.assert_allclose(d[:, 2], z0 + depth * (1 - (rho / radius) ** 2), atol=COORD_TOL_M)
    assert d[:, 2].max() == pytest.approx(apex_z, abs=COORD_TOL_M)


def test_without_the_dish_the_rest_is_unchanged():
    with_dish, without = box_wing(WHITE), box_wing(WHITE, dish=False)
    assert without.part_names == ("bus", "wing_+y", "wing_-y")
    for a, b in zip(with_dish.parts, without.parts, strict=False):
        np.testing.assert_array_equal(a.vertices_m, b.vertices_m)
        np.testing.assert_array_equal(a.faces, b.faces)


def _box_wing_scenario(shape: dict, materials: dict | None = None) -> str:
    d = yaml.safe_load(example_text("box-wing"))
    d["target"]["shape"] = {"builtin": "box_wing", **shape}
    if materials is not None:
        d["target"]["materials"] = materials
    return yaml.safe_dump(d)


def test_dish_false_in_a_scenario():
    loaded = parse_scenario(
        _box_wing_scenario({"dish": False}, {"*": {"bsdf": "lambertian", "reflectance": 0.5}})
    )
    assert build_target(loaded).part_names == ("bus", "wing_+y", "wing_-y")
    with pytest.raises(InputError, match=r"dish: false leaves out the dish; drop dish_radius_m"):
        parse_scenario(_box_wing_scenario({"dish": False, "dish_radius_m": 0.3}))
    # the example names a material for the antenna, which is no part any more
    loaded = parse_scenario(_box_wing_scenario({"dish": False}))
    with pytest.raises(InputError, match=r"part 'antenna', which is not in the shape"):
        build_target(loaded)
    sphere = _box_wing_scenario({"dish": False}).replace("builtin: box_wing", "builtin: sphere")
    with pytest.raises(InputError, match=r"builtin 'sphere' takes radius_m, not dish"):
        parse_scenario(sphere.replace("dish: false", "dish: false\n    radius_m: 1.0"))
