"""Sweep files (``SWEEP.yaml``): read and check them, and expand them into cases.

A sweep file (``docs/sweep.md``) names a ``base`` scenario and the scenario fields to
``vary``, by dotted path (``attitude.period_s``, ``instrument.bands.0.gaussian.center_nm``):

* a list of values is one axis of a product grid;
* ``zip:`` holds fields whose lists have the same length and vary together (one axis:
  ``orbit.tle_file`` and ``orbit.norad_id`` of the same satellites);
* ``{uniform: [a, b]}``, ``{normal: [mu, sigma]}``, ``{loguniform: [a, b]}`` or
  ``{choice: [...]}`` is a random distribution, drawn ``draws`` times per grid point.

Cases come in a fixed order: the grid axes in file order (the first one slowest), then the
draws. Draw ``d`` of grid point ``g`` uses its own generator, ``numpy.random.default_rng(
[seed, g, d])``, so the same file gives the same cases and a larger ``draws`` keeps the earlier
draws. ``set:`` fixes fields for every case (not stored as parameters). Errors name the file,
the line, the field, the value and what is accepted, as the scenario loader's do.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import yaml

from speclight.errors import InputError, did_you_mean
from speclight.input_files import read_user_text
from speclight.scale.sweep_spec import Axis, Distribution, Field, SweepSpec
from speclight.scenario.dotted_fields import field_problem, split_field
from speclight.scenario.load import _ScenarioLoader

TOP_KEYS = ("base", "vary", "set", "draws", "seed", "spectra")
DISTRIBUTIONS = ("uniform", "normal", "loguniform", "choice")
ZIP_KEY = "zip"
#: Most cases a sweep file may expand into: every case is built, validated and held in
#: memory before any runs (:mod:`.sweep_cases`), at about :data:`PLAN_SECONDS_PER_CASE` and
#: :data:`PLAN_BYTES_PER_CASE` each: 100,000 cases take about 7 min and 0.3 GB before the
#: first case runs. Larger studies are several files appended to one store (``--append``).
MAX_CASES = 100_000
#: Building and validating one case (measured: 2,000 calsphere cases in 8.5 s on 2 cores).
PLAN_SECONDS_PER_CASE = 4.3e-3
#: One planned case in memory: its scenario text (JSON, 1.7 kB for the calsphere) and values
#: (measured: 5.5 MiB of peak RSS for 2,000 cases).
PLAN_BYTES_PER_CASE = 2_900
MAX_SWEEP_BYTES = 1024 * 1024


def load_sweep(path: str | Path) -> SweepSpec:
    """Read and check a sweep file (see the module docstring)."""
    path = Path(path)
    text = read_user_text(path, what="sweep file", max_bytes=MAX_SWEEP_BYTES)
    return parse_sweep(text, source=str(path), folder=path.resolve().parent)


def parse_sweep(text: str, source: str = "<sweep>", folder: Path | None = None) -> SweepSpec:
    """Check sweep YAML text; ``folder`` is where a relative ``base`` file is looked for."""
    try:
        loader = _ScenarioLoader(text)
        try:
            root = loader.get_single_node()
            data = loader.construct_document(root) if root is not None else None
        finally:
            loader.dispose()
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"{source}:{mark.line + 1}:{mark.column + 1}" if mark else source
        problem = getattr(exc, "problem", None) or str(exc)
        raise InputError(f"not valid YAML: {problem}", source=where) from None
    except RecursionError:
        raise InputError("nested too deeply for a sweep file", source=source) from None
    return _Checker(source, folder or Path.cwd(), text).check(data, root)


def _line(node: yaml.Node | None, key: str) -> int:
    """Line of ``key`` in a mapping node (of the node itself if the key is absent)."""
    if isinstance(node, yaml.MappingNode):
        for k, _ in node.value:
            if isinstance(k, yaml.ScalarNode) and k.value == key:
                return int(k.start_mark.line) + 1
    return int(node.start_mark.line) + 1 if node is not None else 1


def _child(node: yaml.Node | None, key: str) -> yaml.Node | None:
    if isinstance(node, yaml.MappingNode):
        for k, v in node.value:
            if isinstance(k, yaml.ScalarNode) and k.value == key:
                return v
    return None


def _number(x: Any) -> bool:
    return isinstance(x, int | float) and not isinstance(x, bool) and math.isfinite(x)


class _Checker:
    def __init__(self, source: str, folder: Path, text: str) -> None:
        self.source, self.folder, self.text = source, folder, text
        self.fields: list[Field] = []  # set and varied: no two may overlap
        self.varied: list[Field] = []

    def error(self, line: int, what: str, value: Any, message: str) -> InputError:
        shown = f" = {value!r}" if value is not None else ""
        return InputError(f"line {line}: {what}{shown}: {message}", source=self.source)

    def _top_keys(self, data: Any, root: yaml.Node | None) -> None:
        """A mapping of known keys, with base and vary."""
        if not isinstance(data, dict):
            raise InputError(
                "a sweep file is a YAML mapping with base, vary (and set, draws, seed, "
                f"spectra), got {type(data).__name__}",
                source=self.source,
            )
        for key in data:
            if key not in TOP_KEYS:
                raise self.error(
                    _line(root, str(key)),
                    str(key),
                    None,
                    f"unknown key{did_you_mean(str(key), TOP_KEYS)} "
                    f"(accepted keys: {', '.join(TOP_KEYS)})",
                )
        for key in ("base", "vary"):
            if key not in data:
                raise InputError(
                    f"missing required key '{key}' (base: a built-in example name or a "
                    "scenario file; vary: the fields to vary)",
                    source=self.source,
                )

    def _check_draws(
        self, root: yaml.Node | None, random: bool, seed: int | None, draws: int
    ) -> None:
        """Random distributions need a seed; several draws need a random distribution."""
        if random and seed is None:
            raise self.error(
                _line(root, "vary"),
                "seed",
                None,
                "vary has random distributions: give seed: N (an integer >= 0) so that the "
                "same file gives the same cases",
            )
        if not random and draws > 1:
            raise self.error(
                _line(root, "draws"),
                "draws",
                draws,
                "without a random distribution in vary every draw is the same case; "
                "remove draws or vary a field with {uniform: [a, b]} (or normal, loguniform, "
                "choice)",
            )

    def check(self, data: Any, root: yaml.Node | None) -> SweepSpec:
        self._top_keys(data, root)
        base = data["base"]
        if not isinstance(base, str) or not base.strip():
            raise self.error(
                _line(root, "base"),
                "base",
                base,
                "give a built-in example name (speclight example) or a scenario file path",
            )
        draws = self._integer(data, root, "draws", 1, minimum=1) or 1
        seed = self._integer(data, root, "seed", None, minimum=0)
        spectra = data.get("spectra", False)
        if not isinstance(spectra, bool):
            raise self.error(_line(root, "spectra"), "spectra", spectra, "accepted: true, false")
        fixed = self._set(data.get("set", {}), _child(root, "set"), _line(root, "set"))
        axes, dists = self._vary(data["vary"], _child(root, "vary"), _line(root, "vary"))
        self._check_draws(root, bool(dists), seed, draws)
        spec = SweepSpec(
            self.source,
            self.folder,
            self.text,
            base.strip(),
            _line(root, "base"),
            tuple(self.varied),
            tuple(axes),
            tuple(dists),
            tuple(fixed),
            draws,
            seed,
            spectra,
        )
        if spec.n_cases > MAX_CASES:
            raise self.error(
                _line(root, "vary"),
                "vary",
                None,
                f"{spec.n_cases} cases (grid {spec.n_grid} x draws {draws}) would be built and "
                f"validated before any runs, about "
                f"{spec.n_cases * PLAN_SECONDS_PER_CASE / 60:.3g} min and "
                f"{spec.n_cases * PLAN_BYTES_PER_CASE / 1024**3:.3g} GiB; at most {MAX_CASES} "
                "are accepted per file: split the sweep into several files and run them into "
                "one store with --append",
            )
        return spec

    def _integer(
        self, data: dict[str, Any], root: Any, key: str, default: int | None, minimum: int
    ) -> int | None:
        if key not in data:
            return default
        value = data[key]
        if not isinstance(value, int) or isinstance(value, bool) or value < minimum:
            raise self.error(_line(root, key), key, value, f"must be an integer >= {minimum}")
        return int(value)

    def _field(self, name: Any, line: int, where: str) -> Field:
        if not isinstance(name, str) or not name.strip():
            raise self.error(
                line,
                where,
                name,
                "a field is a dotted scenario path, e.g. "
                "attitude.period_s or instrument.bands.0.gaussian.center_nm",
            )
        path = split_field(name)
        problem = field_problem(path)
        if problem:
            raise self.error(line, f"{where}.{name}", None, problem)
        for other in self.fields:
            shorter = min(len(path), len(other.path))
            # set: is applied first: a varied field inside a set section is fine
            inside_set = other not in self.varied and len(other.path) < len(path)
            if path[:shorter] == other.path[:shorter] and not inside_set:
                again = "is given twice" if path == other.path else f"overlaps {other.name}"
                raise self.error(
                    line, f"{where}.{name}", None, f"{again} (line {other.line}); keep one"
                )
        f = Field(name, path, line)
        self.fields.append(f)
        if where != "set":
            self.varied.append(f)
        return f

    def _set(self, data: Any, node: Any, line: int) -> list[tuple[Field, Any]]:
        if not isinstance(data, dict):
            raise self.error(line, "set", data, "a mapping of dotted fields to fixed values")
        return [(self._field(k, _line(node, str(k)), "set"), v) for k, v in data.items()]

    def _vary(self, data: Any, node: Any, line: int) -> tuple[list[Axis], list[Distribution]]:
        if not isinstance(data, dict) or not data:
            raise self.error(
                line,
                "vary",
                data,
                "a mapping of dotted fields to a list of values or one distribution, e.g. "
                "attitude.period_s: [10, 20] or target.materials.body.reflectance: "
                "{uniform: [0.2, 0.9]}",
            )
        axes: list[Axis] = []
        dists: list[Distribution] = []
        for key, value in data.items():
            key_line = _line(node, str(key))
            if key == ZIP_KEY:
                groups = value if isinstance(value, list) else [value]
                for k, group in enumerate(groups):
                    sub = _child(node, ZIP_KEY)
                    if isinstance(sub, yaml.SequenceNode):
                        sub = sub.value[k]
                    axes.append(self._zip(group, sub, key_line))
                continue
            f = self._field(key, key_line, "vary")
            if isinstance(value, list):
                if not value:
                    raise self.error(key_line, f"vary.{key}", value, "give at least one value")
                axes.append(Axis((f,), tuple((v,) for v in value)))
            elif isinstance(value, dict):
                dists.append(self._distribution(f, value))
            else:
                raise self.error(
                    key_line,
                    f"vary.{key}",
                    value,
                    "give a list of values ([a, b, ...]) or one distribution ({uniform: "
                    "[a, b]}, {normal: [mu, sigma]}, {loguniform: [a, b]}, {choice: [...]}); "
                    "to fix a field for every case use set:",
                )
        return axes, dists

    def _zip(self, group: Any, node: Any, line: int) -> Axis:
        if not isinstance(group, dict) or len(group) < 2:
            raise self.error(
                line,
                "vary.zip",
                group,
                "a mapping of two or more fields to lists of the same length (or a list of "
                "such mappings), e.g. {orbit.tle_file: [a.tle, b.tle], orbit.norad_id: "
                "[1520, 900]}",
            )
        fields: list[Field] = []
        lists: list[list[Any]] = []
        for key, value in group.items():
            key_line = _line(node, str(key))
            f = self._field(key, key_line, "vary.zip")
            if not isinstance(value, list) or not value:
                raise self.error(key_line, f"vary.zip.{key}", value, "give a non-empty list")
            if lists and len(value) != len(lists[0]):
                raise self.error(
                    key_line,
                    f"vary.zip.{key}",
                    None,
                    f"has {len(value)} values, {fields[0].name} has {len(lists[0])}: zipped "
                    "lists vary together and need the same length",
                )
            fields.append(f)
            lists.append(value)
        return Axis(tuple(fields), tuple(zip(*lists, strict=True)))

    def _one_distribution(self, f: Field, value: dict[str, Any]) -> None:
        """The mapping names exactly one known distribution."""
        if len(value) == 1 and next(iter(value)) in DISTRIBUTIONS:
            return
        name = str(next(iter(value))) if len(value) == 1 else None
        hint = did_you_mean(name, DISTRIBUTIONS) if name else ""
        raise self.error(
            f.line,
            f"vary.{f.name}",
            value,
            f"one distribution{hint}: {{uniform: [a, b]}}, {{normal: [mu, sigma]}}, "
            "{loguniform: [a, b]} or {choice: [v1, v2, ...]} (or a list of values)",
        )

    def _distribution(self, f: Field, value: dict[str, Any]) -> Distribution:
        where = f"vary.{f.name}"
        self._one_distribution(f, value)
        name, args = next(iter(value.items()))
        if name == "choice":
            if not isinstance(args, list) or not args:
                raise self.error(f.line, where, value, "choice needs a non-empty list of values")
            return Distribution(f, name, tuple(args))
        ok = isinstance(args, list) and len(args) == 2 and all(_number(a) for a in args)
        need = {
            "uniform": ("[a, b] with a < b", lambda a, b: a < b),
            "normal": ("[mu, sigma] with sigma > 0", lambda a, b: b > 0),
            "loguniform": ("[a, b] with 0 < a < b", lambda a, b: 0 < a < b),
        }[name]
        if not ok or not need[1](*args):
            raise self.error(f.line, where, value, f"{name} takes two numbers {need[0]}")
        return Distribution(f, name, (float(args[0]), float(args[1])))
