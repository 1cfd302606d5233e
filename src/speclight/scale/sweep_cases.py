"""A sweep's cases: the base scenario with each case's fields set, every one validated before
anything runs.

The first invalid case is reported with the sweep file's line of the field that made it
invalid. All cases must share the time grid and the band names (and, with spectra, the
wavelength grid): they are the ``time``, ``band`` (``wavelength``) axes of the store, so a
sweep that varies the time window or the number of bands is refused here (run one sweep per
window).
"""

from __future__ import annotations

import copy
import hashlib
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from numpy.typing import NDArray
from pydantic import ValidationError

from speclight.errors import InputError, did_you_mean
from speclight.scale.sweep_spec import Field, SweepSpec
from speclight.scenario import LoadedScenario, Scenario, load_scenario, parse_scenario
from speclight.scenario.builtin_examples import example_names, example_text
from speclight.scenario.dotted_fields import Path_, set_field
from speclight.scenario.engines import check_engines
from speclight.scenario.load import data_path
from speclight.simulation.geometry_stage import time_grid
from speclight.simulation.memory import check_run_limits, grid_epochs
from speclight.simulation.radiometry import wavelength_grid_nm


@dataclass(frozen=True)
class CaseTask:
    """What a worker needs to run one case (plain data: it is pickled to the worker)."""

    index: int
    yaml_text: str
    source: str
    base_dir: str
    spectra: bool


@dataclass
class SweepPlan:
    """Every case of a sweep file, validated, and the axes they share."""

    spec: SweepSpec
    base: LoadedScenario
    values: list[dict[str, Any]]
    tasks: list[CaseTask]
    time_utc: NDArray[np.datetime64]
    band_names: list[str]
    wavelength_nm: NDArray[np.float64]
    noise: bool
    sha256: str
    #: Some case has ``render.polarization``: the store keeps ``dolp`` and ``aolp``.
    polarization: bool = False
    #: The largest estimated peak memory of a case [bytes] (one case per worker at a time).
    case_bytes: int = 0


def load_base(spec: SweepSpec) -> LoadedScenario:
    """The ``base`` scenario: a built-in example, or a file relative to the sweep file.

    Relative paths inside the cases (``orbit.tle_file``, meshes, tables) resolve against the
    base scenario's folder; for a built-in example, the sweep file's folder.
    """
    names = example_names()
    if spec.base in names:
        return parse_scenario(
            example_text(spec.base), source=f"example '{spec.base}'", base_dir=spec.folder
        )
    path = Path(spec.base).expanduser()
    path = path if path.is_absolute() else spec.folder / path
    if not path.exists() and "/" not in spec.base and not spec.base.endswith((".yaml", ".yml")):
        raise InputError(
            f"line {spec.base_line}: base = {spec.base!r}: no built-in example of that name"
            f"{did_you_mean(spec.base, names)} (choices: {', '.join(names)}) and no such file "
            f"in {spec.folder}",
            source=spec.source,
        )
    return load_scenario(path)


def plan_sweep(spec: SweepSpec, base: LoadedScenario | None = None) -> SweepPlan:
    """Build and validate every case of ``spec`` (see the module docstring)."""
    base = base or load_base(spec)
    base_data = yaml.safe_load(base.yaml_text)
    fixed_data = copy.deepcopy(base_data)
    for f, value in spec.fixed:
        _set(spec, fixed_data, f, value, "set")
    values = spec.case_values()
    fixed = _validate(spec, fixed_data, None, {}) if spec.fixed else base.scenario
    varied_sections = {f.path[0] for f in spec.fields}
    tasks: list[CaseTask] = []
    first: Scenario | None = None
    noise = polarization = False
    case_bytes = 0
    for i, case in enumerate(values):
        data = copy.deepcopy({k: v for k, v in fixed_data.items() if k in varied_sections})
        for f in spec.fields:
            _set(spec, data, f, case[f.name], "vary")
        # sections no field changes are the validated ones of the base (pydantic does not
        # validate a model instance again): only the varied sections are checked per case
        sc = _validate(spec, {**fixed_data, **_sections(fixed), **data}, i, case)
        first = first or sc
        _same_axes(spec, first, sc, i, case)
        noise = noise or bool(sc.instrument.noise and sc.instrument.noise.enabled)
        polarization = polarization or sc.render.polarization
        source = f"{spec.source} case {i}"
        try:
            check_engines(sc, source)
            estimate = check_run_limits(
                LoadedScenario(sc, "", source, base.base_dir), grid_epochs(sc)
            )
        except InputError as exc:
            raise InputError(
                f"case {i} ({_shown(case)}): {exc.message}", source=spec.source, field=exc.field
            ) from None
        case_bytes = max(case_bytes, estimate.total_bytes)
        # JSON is YAML: the worker reads it with the scenario loader (and fast)
        text = json.dumps({**fixed_data, **data}, default=str)
        tasks.append(CaseTask(i, text, source, str(base.base_dir), spec.spectra))
    assert first is not None  # vary is never empty
    if first.target is None and first.render.mode != "map":
        raise InputError(
            f"line {spec.base_line}: base = {spec.base!r} has no target: a sweep stores light "
            "curves; give a scenario with a target section",
            source=spec.source,
        )
    if not first.instrument.bands:
        raise InputError(
            f"line {spec.base_line}: base = {spec.base!r} has no instrument.bands: a sweep "
            "stores count rates and magnitudes per band; add at least one band",
            source=spec.source,
        )
    digest = {
        "base_yaml": base.yaml_text,
        "base_dir": str(base.base_dir),
        "set": [[f.name, v] for f, v in spec.fixed],
        "fields": [f.name for f in spec.fields],
        "cases": values,
        "spectra": spec.spectra,
    }
    sha = hashlib.sha256(json.dumps(digest, sort_keys=True, default=str).encode()).hexdigest()
    return SweepPlan(
        spec,
        base,
        values,
        tasks,
        time_grid(first.time),
        [b.name for b in first.instrument.bands],
        wavelength_grid_nm(first.spectrum),
        noise,
        sha,
        polarization,
        case_bytes,
    )


def _sections(sc: Scenario) -> dict[str, Any]:
    return {name: getattr(sc, name) for name in sc.model_fields_set}


def _shown(case: dict[str, Any]) -> str:
    text = ", ".join(f"{k} = {v!r}" for k, v in case.items())
    return text if len(text) < 300 else text[:297] + "..."


def _set(spec: SweepSpec, data: dict[str, Any], f: Field, value: Any, where: str) -> None:
    try:
        set_field(data, f.path, value)
    except ValueError as exc:
        raise InputError(f"line {f.line}: {where}.{f.name}: {exc}", source=spec.source) from None


def _validate(
    spec: SweepSpec, data: dict[str, Any], i: int | None, case: dict[str, Any]
) -> Scenario:
    try:
        return Scenario.model_validate(data)
    except ValidationError as exc:
        err = exc.errors()[0]
        path = tuple(data_path(tuple(err["loc"]), data)[0])
        blamed = _blame(spec, path)
        dotted = ".".join(str(p) for p in path) or "(top level)"
        if err["type"] == "extra_forbidden":
            problem = (
                f"the base scenario's {'.'.join(str(p) for p in path[:-1])} does not take "
                f"'{path[-1]}' (its model has other fields); change the base, or set the "
                "section's model with set:"
            )
        else:
            value = _get(data, path)
            shown = "" if isinstance(value, dict) else f" = {value!r}"
            problem = f"{dotted}{shown}: {err['msg'].removeprefix('Value error, ')}"
        where = "set" if blamed in [f for f, _ in spec.fixed] else "vary"
        which = f"case {i} ({_shown(case)})" if i is not None else "the base with set:"
        raise InputError(
            f"line {blamed.line}: {where}.{blamed.name}: {which} is not a valid scenario: "
            f"{problem}",
            source=spec.source,
        ) from None


def _get(data: Any, path: Path_) -> Any:
    for part in path:
        data = data[part]
    return data


def _blame(spec: SweepSpec, path: Path_) -> Field:
    """The varied (or set) field that best explains an error at ``path``."""
    candidates = [*spec.fields, *[f for f, _ in spec.fixed]]

    def overlap(f: Field) -> int:
        n = min(len(f.path), len(path))
        return n if f.path[:n] == path[:n] else -1

    best = max(candidates, key=overlap)
    return best if overlap(best) >= 0 else spec.fields[0]


def _same_axes(
    spec: SweepSpec, first: Scenario, sc: Scenario, i: int, case: dict[str, Any]
) -> None:
    checks = [
        ("time", first.time == sc.time, "the time grid (the store's time axis)"),
        (
            "instrument.bands",
            [b.name for b in first.instrument.bands] == [b.name for b in sc.instrument.bands],
            "the band names (the store's band axis)",
        ),
    ]
    if spec.spectra:
        checks.append(("spectrum", first.spectrum == sc.spectrum, "the wavelength grid"))
    for section, same, what in checks:
        if not same:
            blamed = _blame(spec, (section,))
            raise InputError(
                f"line {blamed.line}: vary.{blamed.name}: case {i} ({_shown(case)}) changes "
                f"{what}; every case of a sweep shares it: run one sweep per {section} setting",
                source=spec.source,
            )
