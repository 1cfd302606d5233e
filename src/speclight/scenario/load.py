"""Read a scenario YAML file into a validated :class:`~speclight.scenario.Scenario`.

Errors are :class:`~speclight.errors.InputError` naming the file and line, the field path,
the value and what is accepted; misspelt keys get a did-you-mean. The file must be UTF-8
text (:func:`~speclight.input_files.read_user_text`); a key given twice in one mapping is an
error (YAML would keep the last silently), and so is nesting deeper than
:data:`MAX_NESTING` levels (a scenario needs about five; far deeper, PyYAML's recursive
parser exhausts Python's stack).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, get_args

import yaml
from pydantic import BaseModel, ValidationError

from speclight.errors import InputError, did_you_mean
from speclight.input_files import read_user_text
from speclight.scenario.engines import check_engines
from speclight.scenario.plausibility import warn_implausible_values
from speclight.scenario.scenario_model import Scenario

#: Largest scenario file read [bytes]; scenarios are a few kB (tables live in their own files).
MAX_SCENARIO_BYTES = 4 * 1024 * 1024
#: Deepest nesting of mappings and lists accepted in a scenario.
MAX_NESTING = 64
_OPENERS = (
    yaml.BlockMappingStartToken,
    yaml.BlockSequenceStartToken,
    yaml.FlowMappingStartToken,
    yaml.FlowSequenceStartToken,
)
_CLOSERS = (yaml.BlockEndToken, yaml.FlowMappingEndToken, yaml.FlowSequenceEndToken)


class _ScenarioLoader(yaml.SafeLoader):
    """PyYAML's safe loader, refusing duplicate keys and locating unreadable values."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        seen: dict[tuple[str, str], yaml.error.Mark] = {}
        for key, _ in node.value:
            if not isinstance(key, yaml.ScalarNode) or key.tag == "tag:yaml.org,2002:merge":
                continue
            first = seen.setdefault((key.tag, key.value), key.start_mark)
            if first is not key.start_mark:
                raise yaml.constructor.ConstructorError(
                    None,
                    None,
                    f"key '{key.value}' is given twice in one mapping, on {_at(first)} and "
                    f"{_at(key.start_mark)}; YAML would keep the last silently: remove one",
                    key.start_mark,
                )
        return super().construct_mapping(node, deep=deep)

    def construct_object(self, node: yaml.Node, deep: bool = False) -> Any:
        try:
            return super().construct_object(node, deep=deep)
        except (ValueError, TypeError, OverflowError) as exc:  # e.g. 2020-13-01, !!int x
            raise yaml.constructor.ConstructorError(
                None, None, f"cannot read {node.value!r} as {node.tag} ({exc})", node.start_mark
            ) from exc


@dataclass(frozen=True)
class LoadedScenario:
    """A validated scenario, its YAML text and the folder relative paths refer to.

    ``yaml_text`` is always the scenario that runs: the text as read while the scenario is
    the one read from it, else the scenario written out as YAML (a copy changed in code,
    e.g. by :func:`~speclight.scenario.overrides.replace_fields`).
    """

    scenario: Scenario
    text_as_read: str
    source: str
    base_dir: Path
    as_read: Scenario | None = field(default=None, repr=False, compare=False)

    @property
    def yaml_text(self) -> str:
        """YAML of the scenario that runs (recorded in every output)."""
        if self.as_read is not None and self.scenario == self.as_read:
            return self.text_as_read
        return scenario_yaml(self.scenario)

    def resolve(self, path: str) -> Path:
        """Resolve a path written in the scenario relative to the scenario's folder."""
        p = Path(path).expanduser()
        return p if p.is_absolute() else self.base_dir / p


def load_scenario(path: str | Path) -> LoadedScenario:
    """Read and validate a scenario file.

    Raises
    ------
    InputError
        If the file is missing, is not valid YAML, a field is invalid, or an engine a field
        needs is not installed (the message says what to install).
    """
    path = Path(path)
    text = read_user_text(path, what="scenario file", max_bytes=MAX_SCENARIO_BYTES)
    return parse_scenario(text, source=str(path), base_dir=path.resolve().parent)


def parse_scenario(
    text: str, source: str = "<scenario>", base_dir: Path | None = None
) -> LoadedScenario:
    """Validate scenario YAML text and check the engines it needs (see :func:`load_scenario`
    and :func:`~speclight.scenario.engines.check_engines`)."""
    try:
        _check_nesting(text, source)
        data = yaml.load(text, Loader=_ScenarioLoader)  # a SafeLoader subclass
        root = yaml.compose(text, Loader=yaml.SafeLoader)
    except RecursionError:  # a backstop: _check_nesting keeps far below Python's limit
        raise InputError(f"nested too deeply (limit {MAX_NESTING} levels)", source=source) from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"{source}:{mark.line + 1}:{mark.column + 1}" if mark else source
        problem = getattr(exc, "problem", None) or str(exc)
        raise InputError(f"not valid YAML: {problem}", source=where) from exc
    if not isinstance(data, dict):
        raise InputError(
            f"a scenario is a YAML mapping of sections (name, time, observer, ...), "
            f"got {type(data).__name__}",
            source=source,
        )
    try:
        scenario = Scenario.model_validate(data)
    except ValidationError as exc:
        raise InputError(_describe(exc, data, root), source=source) from None
    check_engines(scenario, source)  # a missing engine is reported now, not after rendering
    warn_implausible_values(scenario)  # notices for values in a likely wrong unit
    loaded = LoadedScenario(
        scenario, text, source, base_dir or Path.cwd(), as_read=scenario.model_copy(deep=True)
    )
    if scenario.render.mode == "map":
        _check_map_file(loaded)
    return loaded


def scenario_yaml(scenario: Scenario) -> str:
    """A scenario written out as YAML that reads back to an equal scenario."""
    return yaml.safe_dump(scenario.model_dump(mode="json"), sort_keys=False, allow_unicode=True)


def _check_map_file(loaded: LoadedScenario) -> None:
    """``render.mode: map``: the map opens, is complete, matches the grid and bands, and
    serves the lasers (:mod:`speclight.scenario.map_lasers`)."""
    from speclight.maps.map_lookup import check_map_matches, read_header
    from speclight.scenario.map_lasers import check_map_lasers
    from speclight.wavelength_grid import grid_from_range_nm

    sc = loaded.scenario
    assert sc.render.map_file is not None
    try:
        header = read_header(loaded.resolve(sc.render.map_file))
        grid = grid_from_range_nm(sc.spectrum.min_nm, sc.spectrum.max_nm, sc.spectrum.step_nm)
        check_map_matches(header, grid, [band.name for band in sc.instrument.bands])
    except InputError as exc:
        raise InputError(exc.message, source=loaded.source, field=exc.field) from None
    check_map_lasers(sc, loaded.source, header)  # coaxial returns, bistatic phase angles


def _at(mark: yaml.error.Mark) -> str:
    return f"line {mark.line + 1} (column {mark.column + 1})"


def _check_nesting(text: str, source: str) -> None:
    """Refuse nesting deeper than :data:`MAX_NESTING` (from the tokens: no recursion)."""
    depth = 0
    for token in yaml.scan(text, Loader=yaml.SafeLoader):
        if isinstance(token, _OPENERS):
            depth += 1
            if depth > MAX_NESTING:
                mark = token.start_mark
                raise InputError(
                    f"mappings and lists are nested more than {MAX_NESTING} levels deep "
                    "(a scenario needs about five); is this a scenario file?",
                    source=f"{source}:{mark.line + 1}:{mark.column + 1}",
                )
        elif isinstance(token, _CLOSERS):
            depth -= 1


def data_path(loc: tuple[Any, ...], data: Any) -> tuple[list[Any], Any, bool]:
    """Keep the parts of a pydantic error location that index the input data.

    Pydantic inserts union-member tags into locations; they are dropped here. Returns the
    data path, the value found there and whether the full location resolved.
    """
    path: list[Any] = []
    node = data
    for part in loc:
        if isinstance(node, dict) and part in node:
            path.append(part)
            node = node[part]
        elif isinstance(node, list) and isinstance(part, int) and 0 <= part < len(node):
            path.append(part)
            node = node[part]
        elif isinstance(node, dict | list):
            continue  # a union tag or a missing field
    resolved = bool(loc) and (path[-1:] == [loc[-1]])
    return path, node, resolved


def _line(root: Any, path: list[Any]) -> int | None:
    node = root
    line = None
    for part in path:
        if isinstance(node, yaml.MappingNode):
            match = [(k, v) for k, v in node.value if k.value == part]
            if not match:
                break
            key, node = match[0]
            line = key.start_mark.line + 1
        elif isinstance(node, yaml.SequenceNode) and isinstance(part, int):
            node = node.value[part]
            line = node.start_mark.line + 1
        else:
            break
    return line


def _models_in(annotation: Any) -> list[type[BaseModel]]:
    """The pydantic models an annotation can hold (through unions, lists, dicts, Annotated)."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    found: list[type[BaseModel]] = []
    for arg in get_args(annotation):
        found.extend(_models_in(arg))
    return found


def _model_at(loc: tuple[Any, ...]) -> type[BaseModel] | None:
    """The scenario model that validated the mapping at a pydantic error location."""
    candidates: list[type[BaseModel]] = [Scenario]
    for part in loc:
        by_field = [c for c in candidates if part in c.model_fields]
        if by_field:
            candidates = _models_in(by_field[0].model_fields[part].annotation)
            continue
        # a union tag: a model's class name or a discriminator value; else a dict/list index
        tagged = [
            c
            for c in candidates
            if c.__name__ == part
            or _literal_default(c, "model") == part
            or part == c.__name__.lower()
        ]
        if tagged:
            candidates = tagged
    return candidates[0] if len(candidates) == 1 else None


def _literal_default(cls: type[BaseModel], field: str) -> Any:
    info = cls.model_fields.get(field)
    args = get_args(info.annotation) if info else ()
    return args[0] if len(args) == 1 else None


def _suggest_key(key: str, parent_loc: tuple[Any, ...]) -> str:
    """Did-you-mean and the accepted keys for an unknown key."""
    cls = _model_at(parent_loc)
    if cls is None:
        return ""
    fields = list(cls.model_fields)
    return f"{did_you_mean(key, fields)} (accepted keys here: {', '.join(fields)})"


def _describe(exc: ValidationError, data: dict[str, Any], root: Any) -> str:
    lines: dict[str, list[str]] = {}
    for err in exc.errors():
        loc = tuple(err["loc"])
        path, value, _ = data_path(loc, data)
        kind = err["type"]
        if kind == "extra_forbidden":
            key = str(loc[-1])
            parent = path[:-1] if path and path[-1] == key else path
            message = f"unknown key '{key}'{_suggest_key(key, loc[:-1])}"
            path = [*parent, key]
        elif kind == "missing":
            message = f"missing required field '{loc[-1]}'"
            path = [*path, loc[-1]] if path[-1:] != [loc[-1]] else path
        else:
            msg = err["msg"].removeprefix("Value error, ")
            section, _, rest = msg.partition(": ")
            if not loc and section in Scenario.model_fields:  # a rule between sections
                path, msg = [section], rest  # names the section it is about first
            shown = "" if isinstance(value, dict) else f" = {value!r}"
            message = f"{shown}: {msg}" if shown else f": {msg}"
        field = ".".join(str(p) for p in path) or "(top level)"
        line = _line(root, [p for p in path])
        prefix = f"line {line}: " if line else ""
        text = (
            f"{prefix}{field}{message}"
            if message.startswith((" =", ":"))
            else (f"{prefix}{field}: {message}")
        )
        lines.setdefault(field, [])
        if text not in lines[field]:
            lines[field].append(text)
    out = []
    for texts in lines.values():
        if len(texts) > 1:
            out.append(texts[0] + "".join(f"\n      or {t.split(': ', 1)[-1]}" for t in texts[1:]))
        else:
            out.append(texts[0])
    n = len(out)
    head = f"{n} invalid field{'s' if n > 1 else ''} in the scenario"
    return head + "\n  " + "\n  ".join(out)
