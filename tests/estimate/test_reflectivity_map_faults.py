"""Reflectivity-map stores under faults: a full disk, a chunk file cut short or deleted, sizes
that cannot fit (issue 22, items 3 and 10).

A full disk is simulated by the Zarr store's one write function raising ``OSError(ENOSPC)``
after a number of writes. Reference: the same map rendered without faults (the map is
deterministic in single mode: a resumed store must equal it bit for bit, as
test_reflectivity_map.py's resume test requires).
"""

from __future__ import annotations

import errno

import numpy as np
import pytest
from map_scenarios import SPHERE_TARGET, write_scenario
from typer.testing import CliRunner
from zarr.storage import _local as zarr_local

from speclight.cli import app
from speclight.errors import InputError
from speclight.io.output import OutputWriteError
from speclight.maps.map_lookup import load_map
from speclight.maps.writer import map_limits as limits
from speclight.maps.writer.reflectivity_map_run import reflectivity_map

OPTIONS = {"directions": 12, "phase_angles_deg": [0.0, 60.0], "rolls": 2, "chunk": 4}


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    folder = tmp_path_factory.mktemp("ref")
    _, loaded = write_scenario(
        folder, "s.yaml", resolution_px=16, step_nm=100, target=SPHERE_TARGET
    )
    writes = _counting_writes()
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(zarr_local, "_put", writes)
        run = reflectivity_map(loaded, folder / "ref.zarr", **OPTIONS)
    assert run.complete and run.n_chunks == 3
    return loaded, load_map(folder / "ref.zarr").intensity_W_sr_nm, writes.count


def _counting_writes(full_after: int | None = None):
    real = zarr_local._put

    def put(path, value, exclusive=False):
        put.count += 1
        if full_after is not None and put.count > full_after:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(path, value, exclusive=exclusive)

    put.count = 0
    return put


@pytest.mark.parametrize("fraction", [0.0, 0.1, 0.3, 0.6, 0.9])
def test_a_full_disk_stops_the_map_and_the_rerun_resumes_it(
    reference, tmp_path, monkeypatch, fraction
):
    # the disk fills after a fraction of the reference run's writes: during the store's
    # creation (0, 0.1), or between and within chunks; the same call then resumes without
    # --force and gives the reference map
    loaded, want, n_writes = reference
    monkeypatch.setattr(zarr_local, "_put", _counting_writes(int(fraction * n_writes)))
    with pytest.raises(OutputWriteError, match=r"No space left on device.*rerun the same"):
        reflectivity_map(loaded, tmp_path / "m.zarr", **OPTIONS)
    monkeypatch.undo()
    run = reflectivity_map(loaded, tmp_path / "m.zarr", **OPTIONS)
    assert run.complete and not run.failed
    np.testing.assert_array_equal(load_map(tmp_path / "m.zarr").intensity_W_sr_nm, want)


def test_a_full_disk_is_exit_1_in_one_line(reference, tmp_path, monkeypatch):
    loaded, _, n_writes = reference
    monkeypatch.setattr(zarr_local, "_put", _counting_writes(n_writes // 2))
    args = ["reflectivity-map", loaded.source, "-o", str(tmp_path / "m.zarr"), "--chunk", "4"]
    result = CliRunner().invoke(app, [*args, "--directions", "12"])
    assert result.exit_code == 1, result.output
    lines = [line for line in result.output.splitlines() if line.startswith("error:")]
    assert len(lines) == 1 and "No space left on device" in lines[0]
    assert "Traceback" not in result.output


@pytest.mark.parametrize("damage", ["cut", "deleted"])
def test_a_done_chunk_that_does_not_read_back_is_rendered_again(reference, tmp_path, damage):
    loaded, want, _ = reference
    first = reflectivity_map(loaded, tmp_path / "m.zarr", **OPTIONS, max_chunks=2)
    assert first.rendered == 2 and not first.complete
    chunk_file = tmp_path / "m.zarr" / "intensity" / "c" / "1" / "0" / "0" / "0"
    if damage == "cut":
        chunk_file.write_bytes(chunk_file.read_bytes()[:50])
    else:
        chunk_file.unlink()
    again = reflectivity_map(loaded, tmp_path / "m.zarr", **OPTIONS)
    assert again.damaged == [1] and again.rendered == 2 and again.complete
    np.testing.assert_array_equal(load_map(tmp_path / "m.zarr").intensity_W_sr_nm, want)


def test_a_chunk_larger_than_the_map_is_the_whole_map(reference, tmp_path):
    loaded, want, _ = reference
    run = reflectivity_map(loaded, tmp_path / "m.zarr", **{**OPTIONS, "chunk": 10**9})
    assert run.complete and run.n_chunks == 1
    np.testing.assert_array_equal(load_map(tmp_path / "m.zarr").intensity_W_sr_nm, want)


def test_a_chunk_above_the_memory_limit_is_refused_with_the_largest_that_fits(reference):
    loaded, _, _ = reference
    geoms = 3  # phase 0 once, 60 deg at 2 rolls
    one = limits.chunk_bytes(loaded, 1, geoms)
    limit = one + 10_000 * (limits.chunk_bytes(loaded, 2, geoms) - one)  # about 10,000 fit
    with pytest.raises(InputError) as err:
        limits.check_chunk_memory(loaded, 10**6, geoms, limit_bytes=limit)
    message = str(err.value)
    fits = int(message.split("at most ")[1].split()[0])
    assert (
        limits.chunk_bytes(loaded, fits, geoms)
        <= limit
        < limits.chunk_bytes(loaded, fits + 1, geoms)
    )
    assert message.startswith("chunk: chunk = 1000000: a chunk renders 1000000 directions")
    assert "GiB of memory, more than the limit" in message


def test_a_map_larger_than_the_free_disk_is_refused(reference, tmp_path, monkeypatch):
    import shutil

    loaded, _, _ = reference
    usage = shutil.disk_usage(tmp_path)
    monkeypatch.setattr(shutil, "disk_usage", lambda _: usage._replace(free=1024**2))
    with pytest.raises(InputError, match=r"the map needs up to .* on disk, more than the 1 MiB"):
        reflectivity_map(loaded, tmp_path / "m.zarr", **{**OPTIONS, "directions": 10**5})


def test_the_store_bytes_are_the_arrays_the_store_holds(reference, tmp_path):
    import zarr

    loaded, _, _ = reference
    reflectivity_map(loaded, tmp_path / "m.zarr", **OPTIONS)
    group = zarr.open_group(str(tmp_path / "m.zarr"), mode="r")
    held = sum(group[n].nbytes for n in ("intensity", "count_rate") if n in group)
    shapes = {
        "direction": 12,
        "phase": 2,
        "roll": 2,
        "wavelength": group["wavelength"].shape[0],
        "band": len(group.attrs["band_names"]),
    }
    assert limits.store_bytes(shapes) == held
