"""Materials of the analytic models (phong, abg, binomial, microfacet) and lab tables'
extensions: one set of checks and messages for the Python material and the scenario file."""

from __future__ import annotations

import re

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.render.bsdfs import material_bsdf
from speclight.scenario.sections_light import Material as ScenarioMaterial
from speclight.target import Material, Reflectance, material_from_spec
from speclight.target.brdf_fit.directional_albedo import EnergyWarning

PHONG = {"kd": 0.1, "ks": 0.4, "n": 30.0}


@pytest.mark.parametrize(
    ("spec", "key", "message"),
    [
        ({"bsdf": "phong", "coefficients": {**PHONG, "kdd": 1}}, "coefficients",
         "unknown coefficient 'kdd' of bsdf 'phong'; did you mean 'kd'? (accepted: kd, ks, n, "),
        ({"bsdf": "phong", "coefficients": {"kd": 0.1, "ks": 0.4}}, "coefficients",
         "bsdf 'phong' needs coefficients.n"),
        ({"bsdf": "phong", "coefficients": {**PHONG, "n": 0.0}}, "coefficients",
         "coefficients.n = 0.0 must lie in (0, 1e+07]"),
        ({"bsdf": "abg", "coefficients": {"a": 1e-3, "b": 1e-4, "g": "two"}}, "coefficients",
         "coefficients.g = 'two' must be a number"),
        ({"bsdf": "binomial", "coefficients": {"b": [[1.0], [1.0, 2.0]], "c": [[0.0]], "d": 3,
                                               "l1": -5}}, "coefficients",
         "coefficients.b = [[1.0], [1.0, 2.0]]: its rows must have the same length"),
        ({"bsdf": "binomial", "coefficients": {"b": [[1.0]], "c": [[0.0], [0.0]], "d": 3,
                                               "l1": -5}}, "coefficients",
         "coefficients.b has 1 rows and coefficients.c 2"),
        ({"bsdf": "microfacet", "coefficients": {"diffuse": 0.1, "f0": 0.5, "roughness": 0.2,
                                                 "distribution": "gxx"}}, "coefficients",
         "coefficients.distribution = 'gxx' must be one of ggx, beckmann; did you mean 'ggx'?"),
        ({"bsdf": "phong"}, "coefficients", "bsdf 'phong' needs coefficients"),
        ({"bsdf": "lambertian", "reflectance": 0.5, "coefficients": PHONG}, "coefficients",
         "coefficients is not used by bsdf 'lambertian'; remove it (used by: phong, abg"),
        ({"bsdf": "phong", "coefficients": PHONG,
          "reflectance": {"wavelength_nm": [400, 800], "value": [0.2, 0.4]}}, "reflectance",
         "a spectral reflectance of bsdf 'phong' is normalised at coefficients.wavelength_nm"),
        ({"bsdf": "phong", "coefficients": PHONG, "reflectance": {"conductor": "Al"}},
         "reflectance", "bsdf 'phong' takes as reflectance a scale"),
        ({"bsdf": "measured", "brdf_table": "starlink_v1p5_chassis_532nm",
          "extension": "ggx"}, "extension", "extension = 'ggx' must be one of microfacet"),
        ({"bsdf": "measured", "brdf_table": "paint.bsdf", "extension": "abg"}, "extension",
         "extension is not used by bsdf 'measured'"),
    ],
)  # fmt: skip
def test_one_set_of_rules_and_messages(spec, key, message):
    with pytest.raises(InputError) as err:
        material_from_spec("m", spec)
    assert err.value.field == f"target.materials.m.{key}"
    assert err.value.message.startswith(message), err.value.message
    with pytest.raises(ValueError, match=re.escape(message)):
        ScenarioMaterial.model_validate(spec)


def test_coefficients_are_held_immutable():
    given = {"b": [[0.5, 0.0]], "c": [[0.0] * 9 + [-2.0]], "d": 3.0, "l1": -5}
    m = material_from_spec("m", {"bsdf": "binomial", "coefficients": given})
    given["b"][0][0] = 9.0  # the caller's mapping changes; the material does not
    assert m.coefficients is not None and m.coefficients["b"] == ((0.5, 0.0),)
    with pytest.raises(TypeError):
        m.coefficients["d"] = 1.0  # type: ignore[index]
    assert hash(m) == hash(material_from_spec("m", {"bsdf": "binomial", "coefficients": {
        "b": [[0.5, 0.0]], "c": [[0.0] * 9 + [-2.0]], "d": 3.0, "l1": -5}}))  # fmt: skip


def test_spectral_reflectance_is_normalised_at_the_fit_wavelength():
    # R(lambda) / R(532 nm) of a linear reflectance 0.2 at 400 nm .. 0.4 at 800 nm:
    # 0.2 + 0.2 (lambda - 400) / 400, so R(532) = 0.266 (by hand)
    refl = Reflectance.pairs([400.0, 800.0], [0.2, 0.4])
    m = Material("m", "phong", refl, coefficients={**PHONG, "wavelength_nm": 532.0})
    wl = np.array([400.0, 532.0, 800.0])
    factor = material_bsdf(m, "single").main_factor(np.ones(1), wl)
    np.testing.assert_allclose(factor[0], np.array([0.2, 0.266, 0.4]) / 0.266, rtol=1e-12)


def test_a_table_without_a_wavelength_refuses_a_spectral_reflectance(tmp_path):
    # a lab table that does not state its wavelength cannot be coloured by a spectral
    # reflectance (R(lambda) / R(table wavelength) is undefined): an error, not NaN
    table = tmp_path / "t.csv"
    rows = ["phi_i theta_i phi_o theta_o brdf"]
    for ti in (10.0, 40.0):
        rows += [f"{ti} -180 {to} 0 {0.1 + 0.001 * to}" for to in range(-80, 81, 2)]
    table.write_text("\n".join(rows) + "\n")
    refl = Reflectance.pairs([400.0, 800.0], [0.2, 0.4])
    m = Material("m", "measured", refl, brdf_table=str(table))
    with pytest.raises(InputError, match="a spectral reflectance is normalised at the wave"):
        material_bsdf(m, "single").main_factor(np.ones(1), np.array([500.0]))


def test_a_material_that_creates_energy_is_a_notice(tmp_path):
    # Kandula et al. 2025's ABg fit of a bare aluminium chassis (starlink_gen2_surfaces.txt)
    # reflects 1.74 times the light it receives at normal incidence; accepted as given (a
    # published model), with a notice
    coefficients = {"a": 0.01999, "b": 2.285e-6, "g": 2.264}
    with pytest.warns(EnergyWarning, match=r"bsdf abg\) reflects 1\.7\d times the light"):
        material_from_spec("bare", {"bsdf": "abg", "coefficients": coefficients})
    # a table of a uniform f = 1 sr-1: albedo pi (Lambert) where it holds, less where its
    # (bounded) extension does: 3.08 at normal incidence
    table = tmp_path / "bright.csv"
    rows = [f"{ti} -180 {to} 0 1.0" for ti in (5.0, 40.0, 70.0) for to in range(-85, 86)]
    table.write_text("\n".join(rows) + "\n")
    with pytest.warns(EnergyWarning, match=r"bright.csv .* reflects 3\.0\d times"):
        Material("m", "measured", Reflectance.constant(1.0), brdf_table=str(table))
