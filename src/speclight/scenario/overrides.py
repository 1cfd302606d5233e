"""Scenario fields set by dotted name, validated as a file is: ``with_overrides``.

A dotted name walks the scenario's mappings by key and its lists by index:
``attitude.period_s``, ``target.materials.body.roughness``,
``instrument.bands.0.gaussian.center_nm``. The new scenario is written out as YAML and read
back with the same validation and messages as a scenario file (a misspelt field gets a
did-you-mean, a bad value names the field, the value and what is accepted), so its
``yaml_text`` is the scenario that will run.

Scenario models are read-only: an assignment such as ``scenario.time.step_s = 2`` raises and
points here; a change through :func:`with_overrides` cannot leave a half-valid scenario
behind, and nothing can make the recorded YAML disagree with what ran.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import replace
from typing import Any

import yaml

from speclight.errors import InputError
from speclight.scenario.dotted_fields import field_problem, set_field, split_field
from speclight.scenario.load import LoadedScenario, parse_scenario
from speclight.scenario.scenario_model import Scenario

_LINE = re.compile(r"line \d+: ")


def set_dotted(data: Any, name: str, value: Any) -> None:
    """Set ``name`` (dotted, list items by index) in plain scenario data, in place.

    A name that is no field of the scenario model is an error with a did-you-mean (as a
    misspelt key in a file); missing sections on the way are created (the validation then
    says what else they need); an index past a list's end is an error.
    """
    path = split_field(name)
    if not name or any(p == "" for p in path):
        raise InputError(
            f"'{name}' is not a dotted field name (e.g. attitude.period_s)", field=name
        )
    problem = field_problem(path)
    if problem is not None:
        raise InputError(problem, field=name)
    try:
        set_field(data, path, value)
    except ValueError as exc:
        raise InputError(str(exc), field=name) from None


def with_overrides(loaded: LoadedScenario, overrides: Mapping[str, Any]) -> LoadedScenario:
    """A new scenario: ``loaded`` with the dotted fields of ``overrides`` set.

    Parameters
    ----------
    loaded
        The scenario to start from (left unchanged).
    overrides
        ``{dotted name: value}``, e.g. ``{"attitude.period_s": 5.0,
        "target.materials.body.reflectance": 0.5}``. Values are plain data as a YAML file
        would hold them (numbers, text, lists, mappings; times as ISO 8601 text).

    Raises
    ------
    InputError
        A path that does not exist on the way, or a scenario the new values make invalid
        (the message of a scenario file, naming the field).
    """
    data = yaml.safe_load(loaded.yaml_text)
    for name, value in overrides.items():
        set_dotted(data, str(name), _plain(value))
    text = yaml.safe_dump(data, sort_keys=False, allow_unicode=True)
    names = ", ".join(f"{k} = {v!r}" for k, v in overrides.items())
    try:
        return parse_scenario(text, source=loaded.source, base_dir=loaded.base_dir)
    except InputError as exc:
        message = _LINE.sub("", exc.message)  # lines of the generated text mean nothing
        raise InputError(
            f"with the overrides {names}: {message}", source=loaded.source, field=exc.field
        ) from None


def replace_fields(loaded: LoadedScenario, overrides: Mapping[str, Any]) -> LoadedScenario:
    """Like :func:`with_overrides`, for code that sets known-good values in a loop (a fit's
    trial roughness): the model is validated, the YAML is not re-parsed."""
    data = loaded.scenario.model_dump(mode="json")
    for name, value in overrides.items():
        set_dotted(data, str(name), _plain(value))
    return replace(loaded, scenario=Scenario.model_validate(data))


def _plain(value: Any) -> Any:
    """numpy scalars and arrays as the plain numbers and lists YAML writes."""
    if hasattr(value, "tolist"):
        return value.tolist()
    return value
