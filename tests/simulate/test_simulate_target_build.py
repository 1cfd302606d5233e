"""The pipeline builds the target from the validated scenario models (issue 8: rules checked
once, in the scenario layer); the result is the target that the plain-value builder
(``target_from_spec``, the Python users' path) gives for the same values."""

import numpy as np
import pytest
import yaml

from speclight.errors import InputError
from speclight.scenario import parse_scenario
from speclight.scenario.builtin_examples import example_text
from speclight.simulation.reflection import build_target
from speclight.target import target_from_spec


@pytest.mark.parametrize("name", ["box-wing", "calsphere", "lcs1"])
def test_built_target_equals_the_plain_value_builder(name):
    d = yaml.safe_load(example_text(name))
    loaded = parse_scenario(yaml.safe_dump(d), source="test")
    target = build_target(loaded)
    shape = {k: v for k, v in d["target"]["shape"].items()}
    reference = target_from_spec(shape, d["target"]["materials"])
    assert [p.name for p in target.parts] == [p.name for p in reference.parts]
    for p, q in zip(target.parts, reference.parts, strict=True):
        np.testing.assert_array_equal(p.vertices_m, q.vertices_m)
        assert p.material.name == q.material.name and p.material.bsdf == q.material.bsdf
        assert p.material.roughness == q.material.roughness
        wl = np.linspace(300.0, 1200.0, 19)
        np.testing.assert_array_equal(
            p.material.reflectance.evaluate(wl), q.material.reflectance.evaluate(wl)
        )


def test_a_bad_lab_brdf_table_is_refused_when_the_target_is_built(tmp_path):
    # repro fuzz/0191: the table was first read halfway through the render, and the error
    # named the field as a bare 'brdf_table'
    (tmp_path / "brdf.csv").write_bytes(b"\xc8\x00garbage")
    d = yaml.safe_load(example_text("calsphere"))
    d["target"]["materials"]["body"] = {"bsdf": "measured", "brdf_table": "brdf.csv"}
    loaded = parse_scenario(yaml.safe_dump(d), source="test", base_dir=tmp_path)
    with pytest.raises(InputError, match="not UTF-8") as err:
        build_target(loaded)
    assert err.value.field == "target.materials.body.brdf_table"
