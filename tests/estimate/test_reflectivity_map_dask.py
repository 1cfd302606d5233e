"""Reflectivity maps on a real Dask cluster (a LocalCluster of 2 workers, loopback only).

Reference: the serial map (``scheduler="none"``, rendered in this process). Chunks of
directions are independent tasks with their own seeds and the same code on each side, so the
map from the cluster must equal it bit for bit (``np.array_equal`` on every array of the
store, and the same attributes); a resume on the cluster after an interrupted serial run, and
a run that loses a worker mid-way, must give that same store, with every chunk written once
(issue 12, items 2 and 4).
"""

from __future__ import annotations

import os
import signal
from collections import Counter
from importlib import import_module

import numpy as np
import pytest
import xarray
import zarr
from map_scenarios import write_scenario
from typer.testing import CliRunner

from speclight.cli import app
from speclight.maps.writer.reflectivity_map_run import reflectivity_map
from speclight.scale import open_executor

# the module (speclight.estimate exports its function under the same name)
refmap = import_module("speclight.maps.writer.reflectivity_map_run")

#: (example, map options): a passive map (phase angles x rolls) and a laser map whose phase
#: angle 0 carries the coaxial range offsets and histograms.
CASES = {
    "passive": ("box-wing", {"phase_angles_deg": [0, 30, 90], "rolls": 4}),
    "laser": ("box-wing-laser", {"phase_angles_deg": [0]}),
}
GRID = {"directions": 48, "chunk": 10}  # HEALPix nside 2: 48 directions in 5 chunks


@pytest.fixture(scope="module")
def cluster():
    with open_executor("local", n_workers=2) as executor:
        yield executor


def _malloc_trim(_: int) -> str | None:
    return os.environ.get("MALLOC_TRIM_THRESHOLD_")


def test_local_workers_keep_glibc_malloc_defaults(cluster):
    # Dask's nanny would set MALLOC_TRIM_THRESHOLD_, which turns off glibc's dynamic mmap
    # threshold (mallopt(3), M_MMAP_THRESHOLD): a map chunk then rendered 2.1x slower
    # (BENCHMARKS.md). speclight's local cluster starts its workers without it.
    assert [o.result for o in cluster.run(_malloc_trim, [0, 1])] == [None, None]


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    """The serial reference map of each case: (folder, scenario, store)."""
    out = {}
    for name, (example, options) in CASES.items():
        folder = tmp_path_factory.mktemp(name)
        _, loaded = write_scenario(
            folder, f"{name}.yaml", resolution_px=16, step_nm=100, example=example
        )
        run = reflectivity_map(loaded, folder / "serial.zarr", **GRID, **options, scheduler="none")
        assert run.complete and run.rendered == 5
        out[name] = (folder, loaded, folder / "serial.zarr")
    return out


def assert_same_store(a, b) -> None:
    ga, gb = zarr.open_group(str(a), mode="r"), zarr.open_group(str(b), mode="r")
    assert sorted(ga.array_keys()) == sorted(gb.array_keys())
    for name in ga.array_keys():
        x, y = np.asarray(ga[name][...]), np.asarray(gb[name][...])
        assert x.dtype == y.dtype and x.shape == y.shape, name
        assert np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), name
        if x.dtype.kind == "f" and name != "chunk_state":
            assert np.isfinite(x).any(), name  # a real map, not an empty one
    assert dict(ga.attrs) == dict(gb.attrs)


@pytest.mark.parametrize("name", sorted(CASES))
def test_cluster_map_is_bit_identical_to_the_serial_one(cluster, serial, name):
    folder, loaded, reference = serial[name]
    run = reflectivity_map(
        loaded,
        folder / "cluster.zarr",
        **GRID,
        **CASES[name][1],
        scheduler=cluster.client.scheduler.address,
    )
    assert run.complete and run.rendered == 5 and not run.failed
    ds = xarray.open_zarr(folder / "cluster.zarr", consolidated=False)
    assert ds["intensity"].dims == ("direction", "phase", "roll", "wavelength")
    assert ("range_histogram" in ds) == (name == "laser")
    assert_same_store(reference, folder / "cluster.zarr")


def test_resume_on_the_cluster_after_an_interrupted_serial_run(cluster, serial):
    folder, loaded, reference = serial["passive"]
    options = {**GRID, **CASES["passive"][1]}
    part = reflectivity_map(loaded, folder / "resumed.zarr", **options, max_chunks=2)
    assert part.rendered == 2 and not part.complete
    again = reflectivity_map(
        loaded, folder / "resumed.zarr", **options, scheduler=cluster.client.scheduler.address
    )
    assert again.complete and again.skipped == 2 and again.rendered == 3
    assert_same_store(reference, folder / "resumed.zarr")


def test_cli_on_a_scheduler_address_and_bad_workers(cluster, serial):
    folder, _, reference = serial["laser"]
    runner = CliRunner()
    base = ["reflectivity-map", str(folder / "laser.yaml"), "--directions", "48", "--chunk", "10"]
    ok = runner.invoke(
        app,
        [*base, "-o", str(folder / "cli.zarr"), "--scheduler", cluster.client.scheduler.address],
    )
    assert ok.exit_code == 0, ok.output
    assert "dashboard: http://" in ok.output  # announced (stderr, mixed in by the runner)
    assert "48 directions in 5 chunks: rendered 5" in ok.output
    assert_same_store(reference, folder / "cli.zarr")
    # (an unreachable scheduler: tests/scale/test_scale_executor.py, its wait is 10 s here)
    bad = runner.invoke(app, [*base, "-o", str(folder / "bad.zarr"), "--workers", "0"])
    assert bad.exit_code == 2, bad.output
    errors = [line for line in bad.output.splitlines() if line.startswith("error:")]
    assert errors == ["error: --workers: --workers = 0 must be >= 1"], bad.output
    assert not (folder / "bad.zarr").exists()


@pytest.fixture
def slow_case(tmp_path):
    # 12 chunks of 4 directions x 25 geometries at 32 px: long enough (about 0.1 s) to be in
    # flight on a worker when it is killed
    _, loaded = write_scenario(tmp_path, "bw.yaml", resolution_px=32, step_nm=100)
    options = {"directions": 48, "chunk": 4, "phase_angles_deg": [0, 30, 60, 90], "rolls": 8}
    run = reflectivity_map(loaded, tmp_path / "serial.zarr", **options)
    assert run.complete and run.n_chunks == 12
    return tmp_path, loaded, options


def test_killed_worker_costs_only_its_chunks(cluster, slow_case, monkeypatch):
    folder, loaded, options = slow_case
    client = cluster.client
    written: Counter[int] = Counter()
    lost: list[int] = []
    real = refmap.write_chunk

    def write_and_kill(group, outcome):
        written[outcome.item.k] += 1
        if not lost:  # the first chunk back: kill a worker that holds chunks now
            processing = client.processing()
            busy = max(processing, key=lambda w: len(processing[w]))
            lost.append(len(processing[busy]))
            os.kill(client.run(os.getpid, workers=[busy])[busy], signal.SIGKILL)
        real(group, outcome)

    monkeypatch.setattr(refmap, "write_chunk", write_and_kill)
    run = reflectivity_map(
        loaded, folder / "cluster.zarr", **options, scheduler=client.scheduler.address
    )
    assert lost[0] >= 1  # the killed worker held chunks: they were run again elsewhere
    assert run.complete and not run.failed and run.rendered == 12
    assert written == Counter(range(12))  # every chunk written exactly once, none lost
    assert_same_store(folder / "serial.zarr", folder / "cluster.zarr")
    client.wait_for_workers(2, timeout=60)  # the nanny restarted it
