"""The Python API at the package top level: load a scenario, change it, simulate it.

>>> import speclight
>>> scenario = speclight.load("calsphere")                      # doctest: +SKIP
>>> faster = speclight.with_overrides(scenario, {"render.resolution_px": 64})  # doctest: +SKIP
>>> result = speclight.simulate(faster)                          # doctest: +SKIP
>>> result.dataset["ab_magnitude"]                               # doctest: +SKIP

Everything the command line does is reachable from here and from the stage subpackages
(``speclight.estimate`` for the inversions); ``docs/api.md`` lists the functions with
their units and a worked example.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import yaml

from speclight.errors import InputError, did_you_mean
from speclight.scenario import LoadedScenario, example_names, load_scenario, parse_scenario
from speclight.scenario.overrides import with_overrides

if TYPE_CHECKING:
    from speclight.simulation.pipeline import SimulationResult

ScenarioLike = LoadedScenario | str | os.PathLike[str] | Mapping[str, Any]


def load(
    scenario: ScenarioLike, *, base_dir: str | os.PathLike[str] | None = None
) -> LoadedScenario:
    """A validated scenario from a file, a built-in example, YAML text or a mapping.

    Parameters
    ----------
    scenario
        A path to a scenario YAML file; the name of a built-in example (``calsphere``,
        ``box-wing``, ... : :func:`examples`); YAML text (anything with a line break or a
        ``key: value``); a mapping with the file's structure; or an already loaded
        scenario (returned as is).
    base_dir
        The folder relative paths in text or a mapping refer to (default: the working
        folder; a file's own folder for a file).

    Raises
    ------
    InputError
        What a scenario file gets: the field, the value and what is accepted.
    """
    if isinstance(scenario, LoadedScenario):
        return scenario
    base = Path(base_dir) if base_dir is not None else None
    if isinstance(scenario, Mapping):
        text = yaml.safe_dump(dict(scenario), sort_keys=False, allow_unicode=True)
        return parse_scenario(text, source="<mapping>", base_dir=base)
    if isinstance(scenario, os.PathLike):
        return load_scenario(Path(scenario))
    if not isinstance(scenario, str):
        raise InputError(
            f"a scenario is a file path, a built-in example name, YAML text or a mapping; "
            f"got {type(scenario).__name__}",
            field="scenario",
        )
    if "\n" in scenario or ": " in scenario:
        return parse_scenario(scenario, source="<text>", base_dir=base)
    if scenario in example_names():
        from speclight.scenario import load_example

        return load_example(scenario)
    if Path(scenario).expanduser().exists() or scenario.endswith((".yaml", ".yml")):
        return load_scenario(Path(scenario).expanduser())
    names = example_names()
    raise InputError(
        f"'{scenario}' is neither a file nor a built-in example{did_you_mean(scenario, names)} "
        f"(examples: {', '.join(names)}; or give YAML text or a mapping)",
        field="scenario",
    )


def examples() -> list[str]:
    """Names of the built-in example scenarios (:func:`load` takes them)."""
    return example_names()


def simulate(
    scenario: ScenarioLike,
    overrides: Mapping[str, Any] | None = None,
    *,
    progress: bool = False,
) -> SimulationResult:
    """Run a scenario through the pipeline: orbit, attitude, render, atmosphere, instrument
    (and ranging where there are lasers).

    Parameters
    ----------
    scenario
        Anything :func:`load` takes.
    overrides
        Dotted fields to set first (:func:`with_overrides`), e.g.
        ``{"attitude.period_s": 5.0}``.
    progress
        Progress bars on a terminal.

    Returns
    -------
    SimulationResult
        ``.dataset`` (an :class:`xarray.Dataset`, SI units and nm; its ``scenario_yaml``
        attribute is the scenario that ran), ``.notes`` (what a user should read, e.g.
        epochs below the horizon) and ``.geometry``.
    """
    from speclight.simulation.pipeline import simulate as run

    loaded = load(scenario)
    if overrides:
        loaded = with_overrides(loaded, overrides)
    return run(loaded, progress)


__all__ = ["ScenarioLike", "examples", "load", "simulate", "with_overrides"]
