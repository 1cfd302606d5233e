"""``speclight reflectivity-map`` and ``render.mode: map`` from the command line: a run, a
resume, and bad input refused with exit code 2 and a one-line message."""

from __future__ import annotations

from pathlib import Path

import pytest
from map_scenarios import map_scenario_text
from typer.testing import CliRunner

from speclight.cli import app

runner = CliRunner()


@pytest.fixture
def scenario(tmp_path: Path) -> Path:
    path = tmp_path / "bw.yaml"
    path.write_text(map_scenario_text(resolution_px=16, step_nm=100))
    return path


def _run(*args: str):
    return runner.invoke(app, list(args))


def _one_line_error(result, code: int, *words: str) -> None:
    assert result.exit_code == code, result.output
    lines = [line for line in result.output.splitlines() if line.startswith("error:")]
    assert len(lines) == 1, result.output
    for word in words:
        assert word in lines[0], lines[0]


def test_map_written_then_refused_without_force_then_replaced(scenario, tmp_path):
    out = str(tmp_path / "m.zarr")
    ok = _run("reflectivity-map", str(scenario), "-o", out, "--directions", "12", "--chunk", "5")
    assert ok.exit_code == 0, ok.output
    assert "12 directions in 3 chunks: rendered 3" in ok.output
    again = _run("reflectivity-map", str(scenario), "-o", out, "--directions", "12")
    _one_line_error(again, 2, "--output", "complete", "--force")
    forced = _run("reflectivity-map", str(scenario), "-o", out, "--directions", "12", "--force")
    assert forced.exit_code == 0, forced.output


@pytest.mark.parametrize(
    ("options", "words"),
    [
        (["--directions", "11"], ["--directions", "11", ">= 12"]),
        (["--phase-angles-deg", "0,a"], ["--phase-angles-deg", "comma-separated"]),
        (["--phase-angles-deg", "0,180"], ["--phase-angles-deg", "0..179"]),
        (["--phase-angles-deg", "30,30"], ["--phase-angles-deg", "repeats"]),
        (["--rolls", "0", "--phase-angles-deg", "30"], ["--rolls", "1..360"]),
        (["--rolls", "1000000000", "--phase-angles-deg", "30"], ["--rolls", "1..360"]),
        (["--chunk", "0"], ["--chunk", ">= 1"]),
    ],
)
def test_bad_options_exit_2(scenario, tmp_path, options, words):
    result = _run("reflectivity-map", str(scenario), "-o", str(tmp_path / "m.zarr"), *options)
    _one_line_error(result, 2, *words)
    assert not (tmp_path / "m.zarr").exists()


def test_output_is_an_existing_file(scenario, tmp_path):
    (tmp_path / "m.zarr").write_text("not a store")
    result = _run("reflectivity-map", str(scenario), "-o", str(tmp_path / "m.zarr"))
    _one_line_error(result, 2, "--output", "not a Zarr store")


def test_force_never_deletes_a_folder_that_is_not_a_map(scenario, tmp_path):
    folder = tmp_path / "data"
    folder.mkdir()
    (folder / "precious.txt").write_text("keep me")
    result = _run("reflectivity-map", str(scenario), "-o", str(folder), "--force")
    _one_line_error(result, 2, "--output", "not a speclight reflectivity map")
    assert (folder / "precious.txt").read_text() == "keep me"


def _map_scenario(tmp_path: Path, map_file: str, step_nm: int = 100) -> Path:
    path = tmp_path / "pass.yaml"
    render = f"render: {{mode: map, map_file: {map_file}}}"
    path.write_text(map_scenario_text(resolution_px=16, step_nm=step_nm, render=render))
    return path


def test_map_mode_missing_map_file(tmp_path):
    result = _run("simulate", str(_map_scenario(tmp_path, "nowhere.zarr")), "-o", "x.nc")
    _one_line_error(result, 2, "render.map_file", "nowhere.zarr", "does not exist")


def test_map_mode_grid_mismatch(scenario, tmp_path):
    out = str(tmp_path / "m.zarr")
    assert _run("reflectivity-map", str(scenario), "-o", out, "--directions", "12").exit_code == 0
    other_grid = _map_scenario(tmp_path, "m.zarr", step_nm=50)
    result = _run("simulate", str(other_grid), "-o", str(tmp_path / "x.nc"))
    _one_line_error(result, 2, "spectrum", "wavelength grid")
    good = _map_scenario(tmp_path, "m.zarr")
    with pytest.warns(UserWarning, match=r"600 epochs have phase angles outside the map's 0\.\.0"):
        result = _run("simulate", str(good), "-o", str(tmp_path / "y.nc"))
    assert result.exit_code == 0, result.output
    assert (tmp_path / "y.nc").is_file()


def test_map_mode_needs_map_file(tmp_path):
    path = tmp_path / "pass.yaml"
    path.write_text(map_scenario_text(render="render: {mode: map}"))
    result = _run("simulate", str(path), "-o", str(tmp_path / "x.nc"))
    _one_line_error(result, 2, "map_file")


def test_map_mode_refuses_an_unfinished_map(scenario, tmp_path):
    from speclight.maps.writer.reflectivity_map_run import reflectivity_map
    from speclight.scenario import load_scenario

    run = reflectivity_map(
        load_scenario(scenario), tmp_path / "m.zarr", directions=12, chunk=5, max_chunks=1
    )
    assert not run.complete
    result = _run("simulate", str(_map_scenario(tmp_path, "m.zarr")), "-o", str(tmp_path / "x.nc"))
    _one_line_error(result, 2, "render.map_file", "unfinished", "same parameters")
