"""The BSDF models: one table read by every part of speclight that needs to know them.

:data:`BSDF_MODELS` maps each ``bsdf`` name a material can have to what the rest of
speclight needs (STYLE.md item 13, as colour's method registries and pvlib's
``_DC_MODEL_PARAMS``):

* validation (:class:`speclight.target.Material` and the scenario's material model): which
  parameters a model needs or takes, their ranges, which reflectance kinds it accepts, one
  set of messages (:func:`parameter_problems`);
* rendering (:mod:`speclight.render.bsdfs`, one module per model): which render modes
  support it, in which its polarisation is modelled, how the single mode splits it into
  channels (geometric weight times spectral factor), which engines it needs;
* the output's provenance (:mod:`speclight.simulation.input_hashes`): which parameters name a
  file whose bytes are hashed (:func:`bsdf_file_parameters`);
* messages and ``docs/scenario.md`` (its model table is checked against this one).

Adding a model is one entry here and its render module (registered in
:data:`speclight.render.bsdfs.RENDERERS`); the contract test
(``tests/render/test_bsdf_contract.py``) then runs it, with its ``examples``, through the
checks every model must pass: reciprocity, a white-furnace albedo <= 1, and single vs path
agreement where it supports both modes.

A model whose support depends on its parameters (``measured``: a lab table or an RGL
``.bsdf`` file) has one entry per *form*; :func:`bsdf_model` picks the form that applies.

The analytic models fitted to measured tables (``phong``, ``abg``, ``binomial``,
``microfacet``; ``speclight brdf-fit``) take one parameter, ``coefficients``, a mapping
checked by :mod:`speclight.target.brdf_fit.form_coefficients`.
"""

from __future__ import annotations

from collections.abc import Mapping
from functools import cache
from types import MappingProxyType
from typing import Any, Literal

from speclight.errors import InputError, did_you_mean
from speclight.target.brdf_fit.directional_albedo import warn_if_creating_energy
from speclight.target.brdf_fit.form_coefficients import (
    FORMS,
    FrozenCoefficients,
    coefficient_problem,
    evaluate,
)
from speclight.target.brdf_table import DEFAULT_EXTENSION, EXTENSIONS, load_brdf_table
from speclight.target.bsdf_model_types import BsdfModel, BsdfParameter
from speclight.target.rgl_file import check_rgl_material, is_rgl_path

#: The ``bsdf`` names (written out for type checkers; a test checks it against the table).
BsdfName = Literal[
    "lambertian",
    "beckmann",
    "ggx",
    "plastic",
    "specular",
    "measured",
    "phong",
    "abg",
    "binomial",
    "microfacet",
]
#: Largest accepted microfacet roughness alpha (RMS slope); beyond ~1 the models lose meaning.
MAX_ROUGHNESS = 1.0


ROUGHNESS = BsdfParameter(
    "roughness",
    f"microfacet alpha, the RMS slope for Beckmann, 0 < alpha <= {MAX_ROUGHNESS:g}; "
    "'specular' is the smooth limit",
    bounds=(0.0, MAX_ROUGHNESS),
)
DIFFUSE_REFLECTANCE = BsdfParameter(
    "diffuse_reflectance", "the base under the coat: its albedo, a reflectance of any kind"
)
BRDF_TABLE = BsdfParameter(
    "brdf_table",
    "a shipped table name, a CSV file (columns phi_i theta_i phi_o theta_o brdf) or a "
    "spectral RGL .bsdf file",
    names_file=True,
)
EXTENSION = BsdfParameter(
    "extension",
    f"the analytic model fitted to a lab table that holds outside its measured support: "
    f"{', '.join(EXTENSIONS)} (default {DEFAULT_EXTENSION})",
)
COEFFICIENTS = BsdfParameter(
    "coefficients",
    "the analytic model's coefficients, a mapping (docs/brdf-models.md; speclight brdf-fit "
    "writes them)",
)
#: Every parameter some model takes, by name.
PARAMETERS: Mapping[str, BsdfParameter] = MappingProxyType(
    {p.name: p for p in (ROUGHNESS, DIFFUSE_REFLECTANCE, BRDF_TABLE, EXTENSION, COEFFICIENTS)}
)


def _check_rgl(material: Any, where: str) -> None:
    check_rgl_material(str(material.brdf_table), material.reflectance, where)


def _read_lab_table(material: Any, where: str) -> None:
    """Read the lab table and fit its extension now (both cached), not halfway through a
    render."""
    try:
        load_brdf_table(str(material.brdf_table), material.extension or DEFAULT_EXTENSION)
    except InputError as exc:
        raise InputError(exc.message, source=exc.source, field=f"{where}.brdf_table") from None


#: What ``reflectance`` means for the models with a Fresnel term.
_FRESNEL = (
    "the Fresnel reflectance: angle dependent for {conductor: ...} and {dielectric: ...}, "
    "F = 1 scaled by a number or table"
)


def _microfacet(distribution: str, label: str) -> BsdfModel:
    return BsdfModel(
        distribution,
        f"rough surface: Cook-Torrance microfacets with {label} normals "
        "(Walter et al. 2007, doi:10.2312/EGWR/EGSR07/195-206)",
        _FRESNEL,
        required=(ROUGHNESS,),
        polarized_modes=("single", "path"),
        channels="one: D G / (4 cos theta_o) x F(theta_d, lambda)",
        examples=({"bsdf": distribution, "roughness": 0.3, "reflectance": 1.0},),
    )


MEASURED_TABLE = BsdfModel(
    "measured",
    "a measured BRDF table f(theta_h, theta_d) (lab tables measured in the plane of incidence; "
    "Romeiro et al. 2008, doi:10.1007/978-3-540-88693-8_63) inside its support, an analytic "
    "model fitted to it outside",
    "a scale R(lambda) / R(table wavelength) (1: as measured)",
    required=(BRDF_TABLE,),
    optional=(EXTENSION,),
    reflectance_kinds=("constant", "table"),
    reflectance_default=1.0,
    modes=("single",),
    channels="1 + 1: the table f(theta_h, theta_d) cos theta_i inside its support, the "
    "extension f cos theta_i outside it; both x R(lambda) / R(table wavelength)",
    examples=(
        {"bsdf": "measured", "brdf_table": "starlink_v1p5_chassis_532nm"},
        {"bsdf": "measured", "brdf_table": "starlink_v1p5_solar_array_532nm", "extension": "abg"},
    ),
    form="lab table",
    check=_read_lab_table,
)
MEASURED_RGL = BsdfModel(
    "measured",
    "an RGL measured material (Dupuy & Jakob 2018, doi:10.1145/3272127.3275059) through "
    "Mitsuba's measured plugin",
    "a constant scale factor in (0, 1] (1: as measured)",
    required=(BRDF_TABLE,),
    reflectance_kinds=("constant",),
    reflectance_default=1.0,
    channels="one per wavelength node of the file: the plugin's BRDF x hat functions",
    engines=(("mitsuba", "brdf_table"),),
    examples=({"bsdf": "measured", "brdf_table": "paint.bsdf"},),
    form="RGL .bsdf file",
    check=_check_rgl,
)


@cache
def _albedo_checked(name: str, coefficients: FrozenCoefficients, label: str) -> None:
    """Warn (once per model, coefficients and material) when they create energy."""
    warn_if_creating_energy(
        label,
        lambda *c: evaluate(name, coefficients, *c),
        "check its coefficients (speclight brdf-fit holds a fit to at most 1)",
    )


def _check_energy(material: Any, where: str) -> None:
    """A notice when a material's analytic BRDF reflects more than it receives."""
    if isinstance(material.coefficients, FrozenCoefficients):
        label = f"{where} (bsdf {material.bsdf})"
        _albedo_checked(material.bsdf, material.coefficients, label)


def _analytic(name: str, summary: str, *examples: Mapping[str, Any]) -> BsdfModel:
    """An analytic model; an example with a ``reflectance`` key is taken as a whole."""
    return BsdfModel(
        name,
        summary,
        "a scale R(lambda) / R(coefficients.wavelength_nm) (1: as fitted)",
        required=(COEFFICIENTS,),
        reflectance_kinds=("constant", "table"),
        reflectance_default=1.0,
        channels="one: f cos theta_i x R(lambda) / R(coefficients.wavelength_nm)",
        examples=tuple(
            dict(e) if "reflectance" in e else {"bsdf": name, "coefficients": dict(e)}
            for e in examples
        ),
        check=_check_energy,
    )


_ANALYTIC = (
    _analytic(
        "phong",
        "energy-normalised Phong lobe about the mirror direction and a diffuse term "
        "(Lafortune & Willems 1994; lumos-sat's PHONG)",
        {"kd": 0.2, "ks": 0.5, "n": 30.0},
        {  # coloured: scaled by R(lambda) / R(532 nm)
            "bsdf": "phong",
            "coefficients": {"kd": 0.2, "ks": 0.5, "n": 30.0, "wavelength_nm": 532.0},
            "reflectance": {"wavelength_nm": [400.0, 1000.0], "value": [0.6, 0.4]},
        },
    ),
    _analytic(
        "abg",
        "Harvey's ABg scatter A / (B + x^g), x the distance between the view and mirror "
        "directions projected on the surface (Harvey 1976, doi:10.1117/12.954861; Zemax; "
        "lumos-sat's ABG)",
        {"a": 9.737e-5, "b": 8.448e-6, "g": 2.686},  # Kandula et al. 2025's boom
    ),
    _analytic(
        "binomial",
        "Greynolds' binomial model (Greynolds 2015, doi:10.1117/12.2196071; the form lumos-sat "
        "fits to the Starlink tables)",
        {"b": [[0.5, 0.0]], "c": [[0.0] * 9 + [-2.0]], "d": 3.0, "l1": -5},
    ),
    _analytic(
        "microfacet",
        "a diffuse term and a GGX or Beckmann lobe with Schlick's or the exact Fresnel term "
        "(Walter et al. 2007, doi:10.2312/EGWR/EGSR07/195-206)",
        {"diffuse": 0.2, "f0": 0.5, "roughness": 0.2, "distribution": "ggx"},
        {
            "diffuse": 0.1,
            "f0": 0.04,
            "roughness": 0.3,
            "distribution": "beckmann",
            "fresnel": "exact",
        },
    ),
)
assert tuple(m.name for m in _ANALYTIC) == tuple(FORMS)

_MODELS = (
    BsdfModel(
        "lambertian",
        "ideal diffuse reflection (Lambert)",
        "the albedo",
        polarized_modes=("single", "path"),
        channels="one: cos theta_i / pi x albedo(lambda)",
        examples=({"bsdf": "lambertian", "reflectance": 1.0},),
    ),
    _microfacet("beckmann", "Beckmann"),
    _microfacet("ggx", "GGX"),
    BsdfModel(
        "plastic",
        "a diffuse base under a dielectric coat, smooth or Beckmann-rough (Weidlich & Wilkie "
        "2007, doi:10.1145/1321261.1321292)",
        "the coat's dielectric n, k ({dielectric: NAME}; its real index is used)",
        required=(DIFFUSE_REFLECTANCE,),
        optional=(ROUGHNESS,),
        reflectance_kinds=("dielectric",),
        polarized_modes=("single",),
        channels="1 + 33 x 33: the coat (glint or Beckmann lobe) x F(theta_d; n(lambda)), the "
        "base binned bilinearly in (cos theta_i, cos theta_o) x its spectral factors",
        examples=(
            {
                "bsdf": "plastic",
                "roughness": 0.3,
                "reflectance": {"dielectric": "SiO2"},
                "diffuse_reflectance": 1.0,
            },
            {
                "bsdf": "plastic",
                "reflectance": {"dielectric": "Kapton"},
                "diffuse_reflectance": 1.0,
            },
        ),
    ),
    BsdfModel(
        "specular",
        "smooth mirror reflecting the solar disk (path mode: with illumination.solar_disk)",
        _FRESNEL,
        polarized_modes=("single", "path"),
        channels="one: the glint (mirror direction in the solar disk) / Omega_sun x "
        "F(theta_d, lambda)",
        examples=({"bsdf": "specular", "reflectance": 1.0},),
    ),
    BsdfModel(
        "measured",
        f"{MEASURED_TABLE.summary}, or {MEASURED_RGL.summary}",
        f"lab table: {MEASURED_TABLE.reflectance}; RGL file: {MEASURED_RGL.reflectance}",
        required=(BRDF_TABLE,),
        reflectance_default=1.0,
        select=lambda given: (
            MEASURED_RGL if is_rgl_path(given.get("brdf_table")) else MEASURED_TABLE
        ),
    ),
    *_ANALYTIC,
)
#: The models by ``bsdf`` name.
BSDF_MODELS: Mapping[str, BsdfModel] = MappingProxyType({m.name: m for m in _MODELS})
#: The ``bsdf`` names, in table order.
BSDF_NAMES: tuple[str, ...] = tuple(BSDF_MODELS)
#: Every form of every model (a model without forms is its own one form).
BSDF_FORMS: tuple[BsdfModel, ...] = tuple(
    f for m in _MODELS for f in ((MEASURED_TABLE, MEASURED_RGL) if m.select else (m,))
)


def check_bsdf_name(name: str, field: str) -> BsdfModel:
    """The model called ``name``; an InputError naming ``field`` and the choices if none is."""
    if name not in BSDF_MODELS:
        raise InputError(
            f"unknown bsdf '{name}'{did_you_mean(str(name), BSDF_NAMES)} "
            f"(choices: {', '.join(BSDF_NAMES)})",
            field=field,
        )
    return BSDF_MODELS[name]


def bsdf_model(name: str, given: Mapping[str, Any] | None = None) -> BsdfModel:
    """The model (its form, for a model with several) of a material.

    Parameters
    ----------
    name
        A registered ``bsdf`` name.
    given
        The material's parameter values (``{"brdf_table": "x.bsdf"}``): they pick the form.
    """
    model = BSDF_MODELS[name]
    return model.select(given or {}) if model.select is not None else model


def parameter_problems(
    name: str, given: Mapping[str, Any], reflectance_kind: str | None = None
) -> list[tuple[str, str]]:
    """What is wrong with a material's parameters: ``[(key, message), ...]`` (empty if fine).

    Parameters
    ----------
    name
        A registered ``bsdf`` name.
    given
        The parameters (:data:`PARAMETERS`) given, None for those left out.
    reflectance_kind
        The kind of its ``reflectance`` (``constant``, ``table``, ``conductor``,
        ``dielectric``); None skips the check.
    """
    model = bsdf_model(name, given)
    problems = []
    for p in PARAMETERS.values():
        why = _parameter_problem(model, p, given.get(p.name))
        if why is not None:
            problems.append((p.name, why))
    kinds = model.reflectance_kinds
    if reflectance_kind is not None and kinds is not None and reflectance_kind not in kinds:
        problems.append(
            (
                "reflectance",
                f"bsdf '{model.label}' takes as reflectance {model.reflectance}, "
                f"got a {reflectance_kind} reflectance",
            )
        )
    coefficients = given.get("coefficients")
    spectral = reflectance_kind not in (None, "constant")
    if name in FORMS and spectral and isinstance(coefficients, Mapping):
        if "wavelength_nm" not in coefficients:
            problems.append(
                (
                    "reflectance",
                    f"a spectral reflectance of bsdf '{name}' is normalised at "
                    "coefficients.wavelength_nm, which is not given; give it, or a constant "
                    "reflectance",
                )
            )
    return problems


def _parameter_problem(model: BsdfModel, p: BsdfParameter, value: Any) -> str | None:
    """What is wrong with the value of parameter ``p`` (None: left out) for ``model``."""
    if value is None:
        return f"bsdf '{model.name}' needs {p.name} ({p.meaning})" if p in model.required else None
    if not model.takes(p.name):
        users = ", ".join(m.name for m in _MODELS if m.takes(p.name))
        return f"{p.name} is not used by bsdf '{model.name}'; remove it (used by: {users})"
    if p is COEFFICIENTS:
        return coefficient_problem(model.name, value)
    if p is EXTENSION and value not in EXTENSIONS:
        return f"extension = {value!r}{did_you_mean(str(value), EXTENSIONS)} must be one of " + (
            ", ".join(EXTENSIONS)
        )
    return p.range_problem(value)


def bsdf_file_parameters() -> frozenset[str]:
    """Names of the parameters whose values may name a file."""
    return frozenset(p.name for p in PARAMETERS.values() if p.names_file)
