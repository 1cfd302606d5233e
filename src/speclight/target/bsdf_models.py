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
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Literal

from speclight.errors import InputError, did_you_mean
from speclight.target.brdf_table import load_brdf_table
from speclight.target.rgl_file import check_rgl_material, is_rgl_path

#: The ``bsdf`` names (written out for type checkers; a test checks it against the table).
BsdfName = Literal["lambertian", "beckmann", "ggx", "plastic", "specular", "measured"]
#: Largest accepted microfacet roughness alpha (RMS slope); beyond ~1 the models lose meaning.
MAX_ROUGHNESS = 1.0


@dataclass(frozen=True)
class BsdfParameter:
    """A material parameter that some models take (a key of the scenario's material).

    Attributes
    ----------
    name
        The key (and :class:`~speclight.target.Material` field).
    meaning
        What it is, with its unit and range, for messages and docs.
    bounds
        ``(low, high)``: the value must lie in (low, high] (numbers only); None: no range.
    names_file
        The value may name a file (its SHA-256 goes into the output's ``input_files``).
    """

    name: str
    meaning: str
    bounds: tuple[float, float] | None = None
    names_file: bool = False

    def range_problem(self, value: Any) -> str | None:
        """Why ``value`` is out of :attr:`bounds` (None when it is inside)."""
        if self.bounds is None:
            return None
        low, high = self.bounds
        if not low < float(value) <= high:
            return f"{self.name} = {value!r} must lie in ({low:g}, {high:g}] ({self.meaning})"
        return None


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
#: Every parameter some model takes, by name.
PARAMETERS: Mapping[str, BsdfParameter] = MappingProxyType(
    {p.name: p for p in (ROUGHNESS, DIFFUSE_REFLECTANCE, BRDF_TABLE)}
)


@dataclass(frozen=True)
class BsdfModel:
    """One BSDF model (or one form of it, see the module docstring).

    Attributes
    ----------
    name
        The ``bsdf`` value.
    summary
        One line: what it models, with its reference.
    reflectance
        What the material's ``reflectance`` means for it.
    required, optional
        Parameters it needs / may take (any other given is an error).
    reflectance_kinds
        The :class:`~speclight.target.Reflectance` kinds it accepts (None: any).
    reflectance_default
        The ``reflectance`` a Python spec may leave out (None: it must be given).
    modes
        Render modes that support it (``single``, ``path``).
    polarized_modes
        Render modes in which its polarisation is modelled (``render.polarization``).
    channels
        How the single mode splits it: geometric weight(s) [sr-1] times spectral factor(s).
    engines
        Optional engines it needs in every mode: ``(engine, key)``, the engine's name in
        :data:`speclight.engine_packages.ENGINES` and the material key that asks for it.
    examples
        Representative parameters (scenario material mappings) for docs and the contract test.
    form
        For a model with several forms, which one this is ("" otherwise).
    select
        For a model with several forms: the form for given parameter values.
    check
        A further check of a built material (reads files): ``check(material, field)``.
    """

    name: str
    summary: str
    reflectance: str
    required: tuple[BsdfParameter, ...] = ()
    optional: tuple[BsdfParameter, ...] = ()
    reflectance_kinds: tuple[str, ...] | None = None
    reflectance_default: float | None = None
    modes: tuple[str, ...] = ("single", "path")
    polarized_modes: tuple[str, ...] = ()
    channels: str = ""
    engines: tuple[tuple[str, str], ...] = ()
    examples: tuple[Mapping[str, Any], ...] = ()
    form: str = ""
    select: Callable[[Mapping[str, Any]], BsdfModel] | None = field(default=None, repr=False)
    check: Callable[[Any, str], None] | None = field(default=None, repr=False)

    @property
    def label(self) -> str:
        """``name`` or ``name (form)``: for messages and test ids."""
        return f"{self.name} ({self.form})" if self.form else self.name

    def takes(self, parameter: str) -> bool:
        """True when the model needs or may take ``parameter``."""
        return any(p.name == parameter for p in (*self.required, *self.optional))


def _check_rgl(material: Any, where: str) -> None:
    check_rgl_material(str(material.brdf_table), material.reflectance, where)


def _read_lab_table(material: Any, where: str) -> None:
    """Read the lab table now (it is cached), not halfway through a render."""
    try:
        load_brdf_table(str(material.brdf_table))
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
    "Romeiro et al. 2008, doi:10.1007/978-3-540-88693-8_63)",
    "a scale R(lambda) / R(table wavelength) (1: as measured)",
    required=(BRDF_TABLE,),
    reflectance_default=1.0,
    modes=("single",),
    channels="one: f(theta_h, theta_d) cos theta_i x R(lambda) / R(table wavelength)",
    examples=({"bsdf": "measured", "brdf_table": "starlink_v1p5_chassis_532nm"},),
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
    return problems


def _parameter_problem(model: BsdfModel, p: BsdfParameter, value: Any) -> str | None:
    """What is wrong with the value of parameter ``p`` (None: left out) for ``model``."""
    if value is None:
        return f"bsdf '{model.name}' needs {p.name} ({p.meaning})" if p in model.required else None
    if not model.takes(p.name):
        users = ", ".join(m.name for m in _MODELS if m.takes(p.name))
        return f"{p.name} is not used by bsdf '{model.name}'; remove it (used by: {users})"
    return p.range_problem(value)


def bsdf_file_parameters() -> frozenset[str]:
    """Names of the parameters whose values may name a file."""
    return frozenset(p.name for p in PARAMETERS.values() if p.names_file)
