"""Dotted scenario fields (``speclight.with_overrides``, sweep files): parse them, check them
against the scenario model, set them in a scenario's data.

``instrument.bands.0.gaussian.center_nm`` is the path ``("instrument", "bands", 0,
"gaussian", "center_nm")``: a number indexes a list; any other part names a field of a
scenario model (or a key of a mapping such as ``target.materials``).
"""

from __future__ import annotations

import types
from typing import Annotated, Any, Union, get_args, get_origin

from pydantic import BaseModel

from speclight.errors import did_you_mean
from speclight.scenario.scenario_model import Scenario

Path_ = tuple[str | int, ...]


def split_field(name: str) -> Path_:
    """``"a.bands.0.b"`` -> ``("a", "bands", 0, "b")``."""
    return tuple(int(p) if p.isdigit() else p for p in name.strip().split("."))


def _leaves(annotations: list[Any]) -> list[Any]:
    """The plain types an annotation can hold (through Annotated, unions and Optional)."""
    out: list[Any] = []
    stack = list(annotations)
    while stack:
        a = stack.pop(0)
        origin = get_origin(a)
        if origin is Annotated:
            stack.insert(0, get_args(a)[0])
        elif origin is Union or origin is types.UnionType:
            stack[:0] = list(get_args(a))
        elif a is not type(None):
            out.append(a)
    return out


def field_problem(path: Path_) -> str | None:
    """Why ``path`` names no field of the scenario model (with a did-you-mean), or None."""
    current: list[Any] = [Scenario]
    for i, part in enumerate(path):
        following: list[Any] = []
        keys: list[str] = []
        wants_index = False
        for a in _leaves(current):
            origin = get_origin(a)
            if isinstance(a, type) and issubclass(a, BaseModel):
                keys += [k for k in a.model_fields if k not in keys]
                if isinstance(part, str) and part in a.model_fields:
                    following.append(a.model_fields[part].annotation)
            elif origin is dict:
                if isinstance(part, str) and part:
                    following.append(get_args(a)[1])
            elif origin is list:
                wants_index = True
                if isinstance(part, int):
                    following.append(get_args(a)[0])
        if not following:
            where = ".".join(str(p) for p in path[:i]) or "the scenario"
            if keys and isinstance(part, str):
                return (
                    f"no field '{part}' in {where}{did_you_mean(part, keys)} "
                    f"(accepted keys here: {', '.join(keys)})"
                )
            if wants_index:
                return f"{where} is a list: index it with a number, e.g. {where}.0"
            return f"{where} is a single value: it has no field '{part}'"
        current = following
    return None


def set_field(data: dict[str, Any], path: Path_, value: Any) -> None:
    """Set ``path`` in a scenario's data in place (creating missing mappings on the way).

    Raises
    ------
    ValueError
        A list index beyond the base's list, or a value in the way that is no mapping.
    """
    node: Any = data
    for depth, part in enumerate(path[:-1]):
        node = _step(node, part, path[: depth + 1], create=True)
    last = path[-1]
    if isinstance(node, list):
        _index(node, last, path)
        node[int(last)] = value
    elif isinstance(node, dict):
        node[last] = value
    else:  # pragma: no cover - _step refuses non-containers
        raise ValueError(f"{_dotted(path[:-1])} is not a mapping")


def _step(node: Any, part: str | int, so_far: Path_, create: bool) -> Any:
    if isinstance(node, list):
        _index(node, part, so_far)
        return node[int(part)]
    if isinstance(node, dict):
        if node.get(part) is None and create:
            node[part] = {}
        child = node[part]
        if not isinstance(child, dict | list):
            raise ValueError(
                f"{_dotted(so_far)} is {child!r} in the base scenario, not a mapping: "
                f"vary {_dotted(so_far)} itself, or set it to a mapping with set:"
            )
        return child
    raise ValueError(f"{_dotted(so_far[:-1])} is not a mapping")


def _index(node: list[Any], part: str | int, so_far: Path_) -> None:
    if not isinstance(part, int) or not 0 <= part < len(node):
        raise ValueError(
            f"{_dotted(so_far)}: the base scenario's list {_dotted(so_far[:-1])} has "
            f"{len(node)} entries (indices 0..{len(node) - 1})"
        )


def _dotted(path: Path_) -> str:
    return ".".join(str(p) for p in path)
