"""The on-disk array cache: computes once, then reads; survives a broken entry."""

from __future__ import annotations

import os
import re
import socket
import subprocess
import sys
import threading
import time
import warnings
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

from speclight.cache import STALE_TEMP_S, cached_arrays, remove_stale_temps


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
    with pytest.warns(UserWarning, match="truncated or corrupt"):
        again = cached_arrays("demo", {"x": 1}, lambda: {"a": np.zeros(2)})
    np.testing.assert_array_equal(again["a"], np.zeros(2))


def _entry(root: Path) -> Path:
    (entry,) = (root / "demo").glob("*.npz")
    return entry


def test_truncated_entry_is_reported_once_recomputed_and_replaced(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Issue 9, item 7: a cache entry cut short by an interrupted run raised BadZipFile in
    # every later run.
    monkeypatch.setenv("SPECLIGHT_CACHE_DIR", str(tmp_path))
    cached_arrays("demo", {"x": "truncated"}, lambda: {"a": np.arange(1000.0)})
    entry = _entry(tmp_path)
    entry.write_bytes(entry.read_bytes()[: entry.stat().st_size // 2])
    with pytest.warns(
        UserWarning, match=rf"cache entry {entry} cannot be read: it is truncated.*replaced"
    ):
        again = cached_arrays("demo", {"x": "truncated"}, lambda: {"a": np.zeros(2)})
    np.testing.assert_array_equal(again["a"], np.zeros(2))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the replaced entry is read back silently
        read = cached_arrays("demo", {"x": "truncated"}, lambda: pytest.fail("recomputed"))
    np.testing.assert_array_equal(read["a"], np.zeros(2))


@pytest.mark.parametrize("kind", ["other-arrays", "npy-file", "no-key"])
def test_foreign_entry_is_ignored_and_replaced(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, kind: str
) -> None:
    # A file at the entry's name that this key did not write: another program's .npz (it
    # made the 6S reader raise KeyError 'log_t'), a bare .npy, an entry of an older version.
    monkeypatch.setenv("SPECLIGHT_CACHE_DIR", str(tmp_path))
    cached_arrays("demo", {"x": kind}, lambda: {"log_t": np.ones(3)})
    entry = _entry(tmp_path)
    with entry.open("wb") as f:
        if kind == "npy-file":
            np.save(f, np.arange(4))
        elif kind == "other-arrays":
            np.savez(f, something_else=np.arange(4))
        else:
            np.savez(f, log_t=np.full(3, 7.0))
    with pytest.warns(UserWarning, match=rf"cache entry {entry} (is not an|was not written)"):
        again = cached_arrays("demo", {"x": kind}, lambda: {"log_t": np.ones(3)})
    assert set(again) == {"log_t"}
    np.testing.assert_array_equal(again["log_t"], np.ones(3))
    read = cached_arrays("demo", {"x": kind}, lambda: pytest.fail("recomputed"))
    np.testing.assert_array_equal(read["log_t"], np.ones(3))


def test_bad_entry_that_cannot_be_replaced_is_reported_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("SPECLIGHT_CACHE_DIR", str(tmp_path))
    cached_arrays("demo", {"x": "read-only"}, lambda: {"a": np.ones(2)})
    _entry(tmp_path).write_bytes(b"garbage")

    def no_rename(src: str, dst: str) -> None:
        raise PermissionError("read-only cache")

    monkeypatch.setattr(os, "replace", no_rename)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for _ in range(3):
            cached_arrays("demo", {"x": "read-only"}, lambda: {"a": np.zeros(2)})
    assert len([w for w in caught if "cache entry" in str(w.message)]) == 1
    assert not list((tmp_path / "demo").glob(".*"))  # the failed writes left no temp file


def test_interrupted_write_leaves_no_temporary_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("SPECLIGHT_CACHE_DIR", str(tmp_path))

    def interrupted(*args: object, **kwargs: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(np, "savez", interrupted)
    with pytest.raises(KeyboardInterrupt):
        cached_arrays("demo", {"x": "interrupted"}, lambda: {"a": np.ones(2)})
    assert list((tmp_path / "demo").iterdir()) == []


def test_temporary_files_of_dead_writers_or_old_ones_are_removed(tmp_path: Path) -> None:
    host = re.sub(r"[^A-Za-z0-9_.-]", "_", socket.gethostname())
    finished = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                              capture_output=True, text=True, check=True)  # fmt: skip
    dead_pid = int(finished.stdout)
    dead = tmp_path / f".0a1b.{host}-{dead_pid}.x1y2.tmp"
    live = tmp_path / f".0a1b.{host}-{os.getpid()}.x3y4.tmp"
    elsewhere = tmp_path / f".0a1b.otherhost-{dead_pid}.x5y6.tmp"
    old = tmp_path / ".0a1b.k2m3.npz"  # the name of temporary files before this fix
    entry = tmp_path / "0a1b.npz"
    for p in (dead, live, elsewhere, old, entry):
        p.write_bytes(b"")
    an_hour_ago = time.time() - STALE_TEMP_S - 1
    os.utime(old, (an_hour_ago, an_hour_ago))
    assert sorted(remove_stale_temps(tmp_path)) == sorted([dead, old])
    assert live.exists() and elsewhere.exists() and entry.exists()
    # Once old enough, a temporary file is removed whatever wrote it.
    later = time.time() + STALE_TEMP_S + 1
    assert sorted(remove_stale_temps(tmp_path, now_s=later)) == sorted([live, elsewhere])


def test_concurrent_writers_of_one_entry_agree(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("SPECLIGHT_CACHE_DIR", str(tmp_path))
    start = threading.Barrier(8)

    def compute() -> dict[str, np.ndarray]:
        return {"a": np.arange(10_000.0)}

    def worker() -> dict[str, np.ndarray]:
        start.wait()
        return cached_arrays("demo", {"x": "concurrent"}, compute)

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no writer ever sees a half-written entry
        with ThreadPoolExecutor(8) as pool:
            results = [f.result() for f in [pool.submit(worker) for _ in range(8)]]
    for r in results:
        np.testing.assert_array_equal(r["a"], np.arange(10_000.0))
    assert [p.name for p in (tmp_path / "demo").iterdir()] == [_entry(tmp_path).name]
