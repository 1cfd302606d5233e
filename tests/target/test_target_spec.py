"""Scenario values -> reflectances, materials and targets, with helpful errors."""

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.target import material_from_spec, reflectance_from_spec, target_from_spec


def test_every_reflectance_form_of_the_spec(tmp_path):
    (tmp_path / "r.csv").write_text("400,0.2\n800,0.6\n")
    wl = np.array([600.0])
    assert reflectance_from_spec(0.7).evaluate(wl)[0] == 0.7
    assert reflectance_from_spec({"file": "r.csv"}, base_dir=tmp_path).evaluate(wl)[0] == 0.4
    pairs = {"wavelength_nm": [400, 800], "value": [0.1, 0.3]}
    assert reflectance_from_spec(pairs).evaluate(wl)[0] == pytest.approx(0.2)
    assert reflectance_from_spec({"conductor": "Au"}).is_fresnel
    assert reflectance_from_spec({"dielectric": "Kapton"}).kind == "dielectric"
    with pytest.raises(InputError, match="not understood"):
        reflectance_from_spec({"metal": "Al"})


def test_scenario_example_sphere_and_errors():
    t = target_from_spec(
        {"builtin": "sphere", "radius_m": 0.565},
        {"body": {"bsdf": "beckmann", "roughness": 0.12, "reflectance": 0.7}},
    )
    assert t.parts[0].sphere_radius_m == 0.565
    assert t.parts[0].material.roughness == 0.12
    with pytest.raises(InputError, match="did you mean 'roughness'"):
        material_from_spec("m", {"bsdf": "ggx", "roughnes": 0.1, "reflectance": 0.5})
    with pytest.raises(InputError, match="did you mean 'sphere'"):
        target_from_spec(
            {"builtin": "spere", "radius_m": 1},
            {"body": {"bsdf": "lambertian", "reflectance": 0.5}},
        )
    with pytest.raises(InputError, match="parts found: body"):
        target_from_spec(
            {"builtin": "sphere", "radius_m": 1},
            {"hull": {"bsdf": "lambertian", "reflectance": 0.5}},
        )
