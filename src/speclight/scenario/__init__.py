"""Scenario files: validation (pydantic), loading (YAML) and the built-in examples."""

from speclight.scenario.builtin_examples import example_names, example_text, load_example
from speclight.scenario.load import LoadedScenario, load_scenario, parse_scenario
from speclight.scenario.scenario_model import Scenario

__all__ = [
    "LoadedScenario",
    "Scenario",
    "example_names",
    "example_text",
    "load_example",
    "load_scenario",
    "parse_scenario",
]
