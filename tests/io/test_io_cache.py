"""The on-disk array cache: computes once, then reads; survives a broken entry."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from speclight.cache import cached_arrays


def test_computes_once_then_reads(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPECLIGHT_CACHE_DIR", str(tmp_path))
    calls = []

    def compute() -> dict[str, np.ndarray]:
        calls.append(1)
        return {"a": np.arange(3.0)}

    first = cached_arrays("demo", {"x": 1}, compute)
    second = cached_arrays("demo", {"x": 1}, compute)
    other = cached_arrays("demo", {"x": 2}, compute)
    assert len(calls) == 2
    np.testing.assert_array_equal(first["a"], second["a"])
    np.testing.assert_array_equal(other["a"], np.arange(3.0))


def test_corrupt_entry_is_recomputed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPECLIGHT_CACHE_DIR", str(tmp_path))
    cached_arrays("demo", {"x": 1}, lambda: {"a": np.ones(2)})
    (entry,) = (tmp_path / "demo").glob("*.npz")
    entry.write_bytes(b"garbage")
    again = cached_arrays("demo", {"x": 1}, lambda: {"a": np.zeros(2)})
    np.testing.assert_array_equal(again["a"], np.zeros(2))
