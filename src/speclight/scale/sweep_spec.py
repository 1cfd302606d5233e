"""A checked sweep file: its fields, grid axes, distributions, and the cases they expand to.

Cases come in a fixed order: the grid axes in file order (the first one slowest), then the
draws. Draw ``d`` of grid point ``g`` uses its own generator, ``numpy.random.default_rng(
[seed, g, d])``, so the same file gives the same cases and a larger ``draws`` keeps the
earlier draws of every grid point.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from speclight.scenario.dotted_fields import Path_


@dataclass(frozen=True)
class Field:
    """A varied (or set) scenario field: its dotted name, path and line in the sweep file."""

    name: str
    path: Path_
    line: int

    @property
    def param(self) -> str:
        """Its variable in the store: ``param_<name with dots as __>``."""
        return "param_" + self.name.replace(".", "__")


@dataclass(frozen=True)
class Axis:
    """One axis of the grid: one field, or zipped fields; ``steps[k]`` a value per field."""

    fields: tuple[Field, ...]
    steps: tuple[tuple[Any, ...], ...]


@dataclass(frozen=True)
class Distribution:
    """A random distribution of one field."""

    field: Field
    name: str
    args: tuple[Any, ...]

    def draw(self, rng: np.random.Generator) -> Any:
        """One value."""
        if self.name == "uniform":
            return float(rng.uniform(self.args[0], self.args[1]))
        if self.name == "normal":
            return float(rng.normal(self.args[0], self.args[1]))
        if self.name == "loguniform":
            return float(np.exp(rng.uniform(math.log(self.args[0]), math.log(self.args[1]))))
        return self.args[int(rng.integers(len(self.args)))]


@dataclass(frozen=True)
class SweepSpec:
    """A checked sweep file (not yet combined with its base scenario)."""

    source: str
    folder: Path
    text: str
    base: str
    base_line: int
    fields: tuple[Field, ...]
    axes: tuple[Axis, ...]
    distributions: tuple[Distribution, ...]
    fixed: tuple[tuple[Field, Any], ...] = ()
    draws: int = 1
    seed: int | None = None
    spectra: bool = False

    @property
    def n_grid(self) -> int:
        return math.prod(len(a.steps) for a in self.axes)

    @property
    def n_cases(self) -> int:
        return self.n_grid * self.draws

    def case_values(self) -> list[dict[str, Any]]:
        """Every case's varied values, ``{field name: value}`` in file order, in case order."""
        order = [f.name for f in self.fields]
        grid: list[dict[str, Any]] = [{}]
        for axis in self.axes:
            grid = [
                {**point, **{f.name: v for f, v in zip(axis.fields, step, strict=True)}}
                for point in grid
                for step in axis.steps
            ]
        cases = []
        for g, point in enumerate(grid):
            for d in range(self.draws):
                values = dict(point)
                if self.distributions:
                    rng = np.random.default_rng([int(self.seed or 0), g, d])
                    values.update({dist.field.name: dist.draw(rng) for dist in self.distributions})
                cases.append({name: values[name] for name in order})
        return cases
