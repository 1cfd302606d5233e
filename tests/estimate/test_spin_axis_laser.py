"""Spin axis of a box-wing pass lit only by coaxial lasers, with its ranging returns, and the
command line's refusals of laser and ranging input it cannot use (exit code 2, one line).

The pass: the box-wing-laser example with the Sun off and its bistatic station removed (the
seven coaxial lines remain), rendered at 24 px, 100 nm bins, 150 epochs; the map: HEALPix
nside 4 (~15 deg between directions), phase angle 0 only, with range offsets. Pass criterion
(as for the solar passes, tests/estimate/test_spin_axis_box_wing.py): the truth lies within
sqrt(2) grid steps of the best cell or of the reported mirror minimum.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from map_scenarios import map_scenario_text
from typer.testing import CliRunner

from speclight.cli import app
from speclight.estimate.spin_axis.spin_axis_core import angular_distance_deg
from speclight.estimate.spin_axis.spin_axis_run import spin_axis_measured
from speclight.io.netcdf import dataset_bytes
from speclight.maps.writer.reflectivity_map_run import reflectivity_map
from speclight.scenario import load_scenario
from speclight.simulation import simulate

GRID_DEG, PHASES = 10.0, 36
runner = CliRunner()


def _text(sun: bool, lasers: bool) -> str:
    text = map_scenario_text(resolution_px=24, step_nm=100, example="box-wing-laser")
    text = text.replace("step_s: 1.0", "step_s: 4.0")
    text = re.sub(r"    - \{name: wettzell-532.*\n.*\n.*\n", "", text)  # coaxial lines only
    if not sun:
        text = text.replace("sun: true", "sun: false")
    if not lasers:
        text = re.sub(r"  lasers:\n(?:    .*\n|       .*\n)+", "", text)
    return text


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("spin_laser")
    for name, sun, lasers in (("laser", False, True), ("sun", True, False)):
        (folder / f"{name}.yaml").write_text(_text(sun, lasers))
        loaded = load_scenario(folder / f"{name}.yaml")
        (folder / f"{name}.nc").write_bytes(dataset_bytes(simulate(loaded).dataset))
        reflectivity_map(
            loaded, folder / f"{name}.zarr", directions=192, phase_angles_deg=[0], rolls=1
        )
    return folder


def test_laser_pass_axis_recovered(folder) -> None:
    with xr.open_dataset(folder / "laser.nc", engine="h5netcdf") as ds:
        assert not np.any(np.isfinite(ds["reflectance_factor"].values))  # the Sun is off
        assert np.any(np.isfinite(ds["range_offset"].values))
    run = spin_axis_measured(
        load_scenario(folder / "laser.yaml"),
        folder / "laser.nc",
        folder / "laser.zarr",
        grid_deg=GRID_DEG,
        n_phases=PHASES,
    )
    r = run.result
    assert run.light == "laser" and run.ranging_weight > 0  # what the data have, by default
    near = [angular_distance_deg(a[0], a[1], 30.0, 45.0) for a in (r.best, r.mirror)]
    assert min(near) <= np.sqrt(2) * GRID_DEG, (r.best, r.mirror)
    assert r.refined[3] <= min(r.best[3], r.mirror[3])


def _one_line_error(result, *words: str) -> None:
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.splitlines() if line.startswith("error:")]
    assert len(lines) == 1, result.output
    for word in words:
        assert word in lines[0], lines[0]


def test_cli_laser_run_and_bad_input(folder) -> None:
    f = folder
    opts = ["--grid-deg", "30", "--phases", "12", "--no-refine"]
    laser = ["spin-axis", str(f / "laser.yaml"), str(f / "laser.nc"), "--map"]
    out = ["-o", str(f / "axis.nc"), "--ranging-weight", "2"]
    ok = runner.invoke(app, [*laser, str(f / "laser.zarr"), *out, *opts])
    assert ok.exit_code == 0, ok.output
    with xr.open_dataset(f / "axis.nc", engine="h5netcdf") as ds:
        assert ds.attrs["light"] == "laser" and ds.attrs["ranging_weight"] == 2.0
        # coaxial light: the true track is the simulation's observer direction in the body
        lat = ds["track_lat"].sel(solution="scenario").values
    with xr.open_dataset(f / "laser.nc", engine="h5netcdf") as sim:
        o = sim["observer_direction_body"].transpose("time", ...).values
    np.testing.assert_allclose(lat, np.degrees(np.arcsin(o[:, 2])), atol=1e-9)
    new = ["-o", str(f / "new.nc"), *opts]
    # a solar pass has no laser factors
    sun_pass = ["spin-axis", str(f / "sun.yaml"), str(f / "sun.nc"), "--map", str(f / "sun.zarr")]
    _one_line_error(
        runner.invoke(app, [*sun_pass, *new, "--source", "laser"]), "laser_reflectance_factor"
    )
    # ... nor range offsets to fit
    _one_line_error(
        runner.invoke(app, [*sun_pass, *new, "--ranging-weight", "1"]), "--ranging-weight"
    )
    # a map made without lasers has no range offsets
    laser_on_sun_map = [
        "spin-axis",
        str(f / "laser.yaml"),
        str(f / "laser.nc"),
        "--map",
        str(f / "sun.zarr"),
    ]
    _one_line_error(
        runner.invoke(app, [*laser_on_sun_map, *new, "--ranging-weight", "1"]), "range_offset"
    )
    _one_line_error(runner.invoke(app, [*sun_pass, *new, "--source", "moon"]), "--source")
    _one_line_error(
        runner.invoke(app, [*sun_pass, *new, "--ranging-weight", "-1"]), "--ranging-weight"
    )
    assert not (f / "new.nc").exists()
