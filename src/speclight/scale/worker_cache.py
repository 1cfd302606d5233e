"""Per-process cache of things a task builds and cannot ship (Mitsuba scenes, render sessions).

A Dask worker is a long-lived process: a task that needs the target's scene builds it once
per worker and finds it there for the next chunk. In a serial run the "worker" is this
process. The cache is small (a sweep may vary the target case by case): the least recently
used entries go first.
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable
from typing import Any, TypeVar

V = TypeVar("V")

#: Entries kept per process.
MAX_ENTRIES = 4
_CACHE: OrderedDict[str, Any] = OrderedDict()


def worker_cached(key: str, build: Callable[[], V]) -> V:
    """``build()`` once per process for ``key`` (e.g. a hash of the scenario text)."""
    if key in _CACHE:
        _CACHE.move_to_end(key)
        return _CACHE[key]
    value = build()
    _CACHE[key] = value
    while len(_CACHE) > MAX_ENTRIES:
        _CACHE.popitem(last=False)
    return value


def clear() -> None:
    """Forget every entry (tests)."""
    _CACHE.clear()
