"""The table of BSDF models (speclight.target.bsdf_models) and every consumer that reads it.

The models themselves go through tests/render/test_bsdf_contract.py; here: the table is
consistent with the types, the material models, the messages, the hashing and the docs.
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path
from typing import get_args

import pytest

from speclight.errors import InputError
from speclight.scenario.sections_light import Material as ScenarioMaterial
from speclight.simulation.input_hashes import FILE_FIELDS
from speclight.target import Material, Reflectance, material_from_spec
from speclight.target.bsdf_models import (
    BSDF_FORMS,
    BSDF_MODELS,
    MEASURED_RGL,
    PARAMETERS,
    BsdfModel,
    BsdfName,
    bsdf_file_parameters,
    bsdf_model,
    parameter_problems,
)

DOCS = Path(__file__).parents[2] / "docs" / "scenario.md"


def test_literal_names_and_table_agree():
    assert get_args(BsdfName) == tuple(BSDF_MODELS)


def test_both_material_models_hold_every_parameter():
    # a new parameter must be a field of the Python material and of the scenario's
    fields = {f.name for f in dataclasses.fields(Material)}
    assert set(PARAMETERS) <= fields
    assert set(PARAMETERS) <= set(ScenarioMaterial.model_fields)


def test_every_example_is_a_valid_material():
    for form in BSDF_FORMS:
        assert form.examples, f"{form.label} has no example for the contract test and docs"
        for example in form.examples:
            scenario = ScenarioMaterial.model_validate(example)
            assert scenario.model is form
            if form is not MEASURED_RGL:  # its example names a file that does not ship
                assert material_from_spec("m", example).model is form


def test_forms_are_picked_by_the_parameters():
    assert bsdf_model("measured", {"brdf_table": "paint.bsdf"}) is MEASURED_RGL
    assert bsdf_model("measured", {"brdf_table": "starlink_v1p5_chassis_532nm"}).form == (
        "lab table"
    )
    assert bsdf_model("lambertian") is BSDF_MODELS["lambertian"]


@pytest.mark.parametrize(
    ("name", "given", "kind", "key", "message"),
    [
        ("ggx", {}, "constant", "roughness", "bsdf 'ggx' needs roughness (microfacet alpha"),
        (
            "lambertian",
            {"roughness": 0.1},
            "constant",
            "roughness",
            "roughness is not used by bsdf 'lambertian'; remove it (used by: beckmann, ggx, "
            "plastic)",
        ),
        (
            "lambertian",
            {"diffuse_reflectance": 0.5},
            "constant",
            "diffuse_reflectance",
            "diffuse_reflectance is not used by bsdf 'lambertian'",
        ),
        ("plastic", {}, "dielectric", "diffuse_reflectance", "bsdf 'plastic' needs diffuse_"),
        (
            "plastic",
            {"diffuse_reflectance": 0.5},
            "conductor",
            "reflectance",
            "bsdf 'plastic' takes as reflectance the coat's dielectric n, k",
        ),
        ("measured", {}, "constant", "brdf_table", "bsdf 'measured' needs brdf_table"),
        (
            "specular",
            {"brdf_table": "x.csv"},
            "constant",
            "brdf_table",
            "brdf_table is not used by bsdf 'specular'",
        ),
    ],
)
def test_one_set_of_rules_and_messages(name, given, kind, key, message):
    # The same rules (and words) for the Python material and the scenario file.
    problems = parameter_problems(name, given, kind)
    assert problems and problems[0][0] == key and problems[0][1].startswith(message)
    refl = {
        "constant": Reflectance.constant(0.5),
        "dielectric": Reflectance.dielectric("SiO2"),
        "conductor": Reflectance.conductor("Al"),
    }[kind]
    values = {k: Reflectance.constant(v) if k == "diffuse_reflectance" else v
              for k, v in given.items()}  # fmt: skip
    with pytest.raises(InputError) as err:
        Material("m", name, refl, **values)
    assert err.value.field == f"target.materials.m.{key}"
    assert err.value.message == problems[0][1]
    scenario_refl = {"constant": 0.5, "dielectric": {"dielectric": "SiO2"}}.get(
        kind, {"conductor": "Al"}
    )
    with pytest.raises(ValueError, match=re.escape("Value error, " + problems[0][1])):
        ScenarioMaterial.model_validate({"bsdf": name, "reflectance": scenario_refl, **given})


def test_parameter_ranges():
    # the Python material checks the registry's range; the scenario's field has the same
    # bound as a pydantic constraint (checked first, with the line of the file)
    message = "roughness = 1.5 must lie in (0, 1] (microfacet alpha"
    assert parameter_problems("beckmann", {"roughness": 1.5})[0][1].startswith(message)
    with pytest.raises(InputError, match=re.escape(message)):
        Material("m", "beckmann", Reflectance.constant(0.5), roughness=1.5)
    with pytest.raises(ValueError, match="less than or equal to 1"):
        ScenarioMaterial.model_validate({"bsdf": "beckmann", "roughness": 1.5})


def test_file_parameters_are_hashed():
    # the output's input_files records every file a material names
    assert bsdf_file_parameters() == {"brdf_table"}
    assert bsdf_file_parameters() <= FILE_FIELDS


def _docs_row(form: BsdfModel) -> str:
    name = f"`{form.name}`" + (f" ({form.form})" if form.form else "")
    params = [f"`{p.name}`" for p in form.required]
    params += [f"`{p.name}` (optional)" for p in form.optional]
    cells = [
        name,
        form.summary,
        ", ".join(params) or "-",
        form.reflectance,
        ", ".join(form.modes),
        ", ".join(form.polarized_modes) or "-",
        form.channels,
    ]
    return "| " + " | ".join(cells) + " |"


def test_docs_list_every_model_as_the_table_says():
    text = DOCS.read_text()
    for form in BSDF_FORMS:
        assert _docs_row(form) in text, _docs_row(form)
