"""Sweep stores under faults and sizes up front (issue 22, items 3 and 10).

A full disk is simulated by the Zarr store's one write function raising ``OSError(ENOSPC)``
after a number of writes. Reference: the same sweep run without faults (the cases are
deterministic, noise included: a resumed store must equal it bit for bit, as
test_scale_sweep_run.py's serial and cluster stores do). Two runs to one store: the lock
beside it lets one write and refuses the other at once; a case runs once (counted calls).
"""

from __future__ import annotations

import errno
import os
import threading
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from zarr.storage import _local as zarr_local

from speclight.errors import InputError
from speclight.io import store_io
from speclight.io.output import OutputWriteError
from speclight.scale.executor import local_workers
from speclight.scale.sweep_cases import plan_sweep
from speclight.scale.sweep_file import MAX_CASES, load_sweep
from speclight.scale.sweep_run import run_case, run_sweep

SWEEP = """base: calsphere
set:
  render.resolution_px: 16
  time: {start: 2020-02-29T21:16:00Z, stop: 2020-02-29T21:16:20Z, step_s: 4.0}
vary:
"""
ALBEDOS = "  target.materials.body.reflectance: [0.2, 0.4, 0.6, 0.8]\n"
CURVES = ("count_rate", "ab_magnitude", "count_rate_measured")


def _plan(folder: Path, vary: str = ALBEDOS, name: str = "sweep.yaml", extra: str = ""):
    path = folder / name
    path.write_text(SWEEP + vary + extra)
    return plan_sweep(load_sweep(path))


def _counting_writes(full_after: int | None = None):
    real = zarr_local._put

    def put(path, value, exclusive=False):
        put.count += 1
        if full_after is not None and put.count > full_after:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(path, value, exclusive=exclusive)

    put.count = 0
    return put


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    folder = tmp_path_factory.mktemp("ref")
    plan = _plan(folder)
    writes = _counting_writes()
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(zarr_local, "_put", writes)
        run = run_sweep(plan, folder / "ref.zarr", scheduler="none")
    assert run.complete and not run.failed
    return plan, xr.open_zarr(folder / "ref.zarr").load(), writes.count


def _same(path: Path, want: xr.Dataset) -> None:
    got = xr.open_zarr(path).load()
    assert list(got.case_state.values) == [1] * want.sizes["case"]
    for name in CURVES:
        np.testing.assert_array_equal(got[name].values, want[name].values)


@pytest.mark.parametrize("fraction", [0.0, 0.05, 0.2, 0.5, 0.9])
def test_a_full_disk_stops_the_sweep_and_the_rerun_resumes_it(
    reference, tmp_path, monkeypatch, fraction
):
    plan, want, n_writes = reference
    monkeypatch.setattr(zarr_local, "_put", _counting_writes(int(fraction * n_writes)))
    with pytest.raises(OutputWriteError, match=r"No space left on device.*rerun the same"):
        run_sweep(plan, tmp_path / "runs.zarr", scheduler="none")
    monkeypatch.undo()
    run = run_sweep(plan, tmp_path / "runs.zarr", scheduler="none")
    assert run.complete and not run.failed
    _same(tmp_path / "runs.zarr", want)


def test_an_append_cut_short_by_a_full_disk_is_resumed_in_place(reference, tmp_path, monkeypatch):
    _, want, _ = reference
    first = _plan(tmp_path, "  target.materials.body.reflectance: [0.2]\n", "a.yaml")
    more = _plan(tmp_path, "  target.materials.body.reflectance: [0.4, 0.6]\n", "b.yaml")
    out = tmp_path / "runs.zarr"
    run_sweep(first, out, scheduler="none")
    monkeypatch.setattr(zarr_local, "_put", _counting_writes(3))  # while the arrays grow
    with pytest.raises(OutputWriteError):
        run_sweep(more, out, scheduler="none", append=True)
    monkeypatch.undo()
    run = run_sweep(more, out, scheduler="none", append=True)
    assert (run.first_case, run.ran, run.failed) == (1, 2, {})
    got = xr.open_zarr(out).load()
    assert got.sizes["case"] == 3 and list(got.case.values) == [0, 1, 2]
    np.testing.assert_array_equal(got["count_rate"].values, want["count_rate"].values[:3])


def test_a_done_case_that_does_not_read_back_runs_again(reference, tmp_path):
    plan, want, _ = reference
    out = tmp_path / "runs.zarr"
    run_sweep(plan, out, scheduler="none")
    chunk = out / "count_rate" / "c" / "2" / "0" / "0"
    chunk.write_bytes(chunk.read_bytes()[:50])
    run = run_sweep(plan, out, scheduler="none")
    assert run.damaged == [2] and (run.ran, run.skipped) == (1, 3)
    _same(out, want)


_calls: list[int] = []


def _slow_case(task):
    _calls.append(task.index)
    time.sleep(0.5)
    return run_case(task)


def test_two_runs_to_one_store_never_run_a_case_twice(reference, tmp_path):
    plan, want, _ = reference
    out = tmp_path / "runs.zarr"
    _calls.clear()
    first = threading.Thread(
        target=run_sweep, args=(plan, out), kwargs={"scheduler": "none", "task": _slow_case}
    )
    first.start()
    while not _calls:  # the first run holds the store
        time.sleep(0.05)
    with pytest.raises(InputError, match="another speclight run is writing"):
        run_sweep(plan, out, scheduler="none", task=_slow_case)
    link = tmp_path / "link.zarr"  # another name of the same store takes the same lock
    os.symlink(out, link)
    with pytest.raises(InputError, match="another speclight run is writing"):
        run_sweep(plan, link, scheduler="none", task=_slow_case)
    first.join()
    again = run_sweep(plan, out, scheduler="none", task=_slow_case)  # after it: nothing to do
    assert (again.ran, again.skipped) == (0, 4)
    assert sorted(_calls) == [0, 1, 2, 3]
    _same(out, want)


def test_a_refused_run_leaves_the_holders_lock_in_place(tmp_path):
    store = tmp_path / "runs.zarr"
    lock = tmp_path / ".runs.zarr.speclight.lock"
    with store_io.store_lock(store):
        with pytest.raises(InputError):
            with store_io.store_lock(store):
                pass
        assert lock.exists()  # a third run is refused too
        with pytest.raises(InputError):
            with store_io.store_lock(store):
                pass
    assert not lock.exists()


def test_a_lock_file_on_a_full_disk_is_one_write_error(tmp_path, monkeypatch):
    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(store_io.os, "open", full)
    with pytest.raises(OutputWriteError, match=r"cannot write .*runs\.zarr: No space left"):
        with store_io.store_lock(tmp_path / "runs.zarr"):
            pass


def test_a_sweep_file_of_a_million_cases_is_refused_with_its_estimate(tmp_path):
    path = tmp_path / "big.yaml"
    path.write_text(
        SWEEP + "  target.materials.body.reflectance: {uniform: [0.1, 0.9]}\n"
        "draws: 1000000\nseed: 1\n"
    )
    started = time.perf_counter()
    with pytest.raises(InputError) as err:
        load_sweep(path)
    assert time.perf_counter() - started < 5.0  # refused before any case is built
    message = str(err.value)
    assert "1000000 cases (grid 1 x draws 1000000)" in message
    assert f"at most {MAX_CASES}" in message and "--append" in message
    assert " min and " in message and "GiB" in message


def test_a_draw_outside_a_fields_range_is_refused_before_any_case_runs(tmp_path):
    with pytest.raises(InputError, match=r"case \d+ .*optics_transmission.*fraction in 0\.\.1"):
        _plan(
            tmp_path,
            "  instrument.optics_transmission: {uniform: [0.6, 1.5]}\n",
            extra="draws: 20\nseed: 1\n",
        )


def test_the_case_bytes_are_the_arrays_a_case_holds(reference, tmp_path):
    from speclight.scale import sweep_store

    plan, want, _ = reference
    held = sum(want[name].values[0].nbytes for name in CURVES)
    assert sweep_store.case_bytes(plan) == held


def test_local_workers_are_capped_by_cores_and_memory(monkeypatch):
    monkeypatch.setattr(os, "cpu_count", lambda: 16)
    assert local_workers(None, 0, 10**12) == (16, None)
    workers, note = local_workers(1000, 0, 10**12)
    assert workers == 16 and note == "--workers 1000: using 16 (16 cores here)"
    gib = 1024**3
    workers, note = local_workers(None, 3 * gib, 10 * gib)  # 3 tasks of 3 GiB fit in 10
    assert workers == 3
    assert note is not None and "memory for 3 tasks of 3 GiB under the limit of 10 GiB" in note
    assert local_workers(2, 3 * gib, 10 * gib) == (2, None)
    assert local_workers(None, 30 * gib, 10 * gib)[0] == 1  # one task: its own check refuses
