"""Small scenarios for reflectivity-map tests, derived from the box-wing example."""

from __future__ import annotations

import re
from pathlib import Path

from speclight.scenario import LoadedScenario, load_scenario
from speclight.scenario.builtin_examples import example_text

SPHERE_TARGET = """target:
  shape: {builtin: sphere, radius_m: 1.7}
  materials:
    body: {bsdf: lambertian, reflectance: 0.6}
"""


def map_scenario_text(
    resolution_px: int = 32,
    step_nm: int = 20,
    target: str | None = None,
    render: str | None = None,
    example: str = "box-wing",
) -> str:
    """The box-wing example with a coarser render and grid; another target or render line."""
    text = example_text(example)
    text = re.sub(r"resolution_px: \d+", f"resolution_px: {resolution_px}", text)
    text = re.sub(r"step_nm: \d+", f"step_nm: {step_nm}", text)
    if target is not None:
        text = re.sub(r"^target:\n(?:  .*\n)+", target, text, flags=re.M)
    if render is not None:
        text = re.sub(r"render: \{.*\}", render, text)
    return text


def write_scenario(folder: Path, name: str, **kwargs: object) -> tuple[Path, LoadedScenario]:
    """Write :func:`map_scenario_text` to ``folder/name`` and load it."""
    path = folder / name
    path.write_text(map_scenario_text(**kwargs))  # type: ignore[arg-type]
    return path, load_scenario(path)
