"""Built-in example scenarios (``speclight example NAME``)."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from speclight.errors import InputError, did_you_mean
from speclight.scenario.load import LoadedScenario, parse_scenario

_PACKAGE = "speclight.scenario.examples"


def example_names() -> list[str]:
    """Names of the built-in scenarios."""
    files = resources.files(_PACKAGE).iterdir()
    return sorted(f.name.removesuffix(".yaml") for f in files if f.name.endswith(".yaml"))


def example_text(name: str) -> str:
    """YAML text of a built-in scenario."""
    names = example_names()
    if name not in names:
        raise InputError(
            f"no built-in example '{name}'{did_you_mean(name, names)} "
            f"(choices: {', '.join(names)})",
            field="example",
        )
    return (resources.files(_PACKAGE) / f"{name}.yaml").read_text()


def load_example(name: str) -> LoadedScenario:
    """Load and validate a built-in scenario; relative paths resolve to the working folder."""
    return parse_scenario(example_text(name), source=f"example '{name}'", base_dir=Path.cwd())
