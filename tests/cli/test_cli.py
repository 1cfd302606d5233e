"""The command line of SPEC section 2: outputs, exit codes and messages."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml
from typer.testing import CliRunner

from speclight.cli import app
from speclight.scenario import example_text

runner = CliRunner()

GEOMETRY_VARIABLES = [
    "range",
    "azimuth",
    "elevation",
    "phase_angle",
    "sunlit",
    "sun_direction_body",
    "observer_direction_body",
    "phase_vector_body",
]


def _short_scenario(tmp_path: Path, name: str = "calsphere", **time: str) -> Path:
    data = yaml.safe_load(example_text(name))
    data["time"].update(time)
    path = tmp_path / "scenario.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_example_lists_and_prints() -> None:
    listed = runner.invoke(app, ["example"])
    assert listed.exit_code == 0
    names = {"box-wing", "calsphere", "cube-materials", "cube-materials-laser", "lcs1"}
    assert names <= set(listed.stdout.split())
    printed = runner.invoke(app, ["example", "lcs1"])
    assert printed.exit_code == 0
    assert yaml.safe_load(printed.stdout)["name"] == "lcs1-pass"


def test_unknown_example_exits_2() -> None:
    result = runner.invoke(app, ["example", "box_wing"])
    assert result.exit_code == 2
    assert "did you mean 'box-wing'" in result.stderr


def test_simulate_edited_copy_writes_geometry(tmp_path: Path) -> None:
    scenario = _short_scenario(tmp_path, stop="2020-02-29T21:15:00Z", step_s=10.0)
    out = tmp_path / "out.nc"
    result = runner.invoke(app, ["simulate", str(scenario), "-o", str(out)])
    assert result.exit_code == 0, result.output
    ds = xr.open_dataset(out)
    assert ds.sizes["time"] == 13
    for name in GEOMETRY_VARIABLES:
        assert "units" in ds[name].attrs and "long_name" in ds[name].attrs
    # unit vectors are unit vectors (a property of the definition, not of the code)
    norms = np.linalg.norm(ds["observer_direction_body"].values, axis=1)
    np.testing.assert_allclose(norms, 1.0, atol=1e-12)
    assert "lcs1" not in ds.attrs["scenario_yaml"] and "calsphere" in ds.attrs["scenario_yaml"]
    assert ds.attrs["speclight_version"]
    ds.close()


def test_existing_output_needs_force(tmp_path: Path) -> None:
    scenario = _short_scenario(tmp_path, stop="2020-02-29T21:13:10Z", step_s=5.0)
    out = tmp_path / "out.nc"
    out.write_text("precious")
    refused = runner.invoke(app, ["simulate", str(scenario), "-o", str(out)])
    assert refused.exit_code == 2
    assert "--force" in refused.stderr
    assert out.read_text() == "precious"
    forced = runner.invoke(app, ["simulate", str(scenario), "-o", str(out), "--force"])
    assert forced.exit_code == 0, forced.output
    assert xr.open_dataset(out).sizes["time"] == 3


def test_bad_scenario_exits_2_without_traceback(tmp_path: Path) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text(example_text("lcs1").replace("step_s: 2.0", "step_s: 0"))
    out = tmp_path / "out.nc"
    result = runner.invoke(app, ["simulate", str(bad), "-o", str(out)])
    assert result.exit_code == 2
    assert "time.step_s = 0" in result.stderr
    assert "Traceback" not in result.output
    assert not out.exists() and not list(tmp_path.glob(".out.nc*"))


def test_window_without_visibility_succeeds_and_says_so(tmp_path: Path) -> None:
    # Calsphere 4A is 45-54 deg below Stuttgart's horizon from 12:00 to 12:05 UTC that day
    # (checked with skyfield directly); the run must still succeed and tell the user.
    scenario = _short_scenario(
        tmp_path, start="2020-02-29T12:00:00Z", stop="2020-02-29T12:05:00Z", step_s=30.0
    )
    out = tmp_path / "out.nc"
    result = runner.invoke(app, ["simulate", str(scenario), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "the target is never observable in this time window" in result.stdout
    ds = xr.open_dataset(out)
    assert np.all(ds["elevation"].values < 10.0)
    assert np.all(ds["flags"].values & 2)


def test_info_reports_versions_and_coverage() -> None:
    result = runner.invoke(app, ["info"])
    assert result.exit_code == 0, result.output
    assert "skyfield" in result.stdout and "eop_measured_until" in result.stdout
    assert "variant in single mode" in result.stdout and "variant in path mode" in result.stdout
    assert "variant in polarised path mode" in result.stdout
    assert "gpu (CUDA)" in result.stdout


def test_console_script_entry_point(tmp_path: Path) -> None:
    # The installed console script, run as a user would.
    exe = Path(sys.executable).with_name("speclight")
    if not exe.exists():
        pytest.skip("speclight console script not installed in this environment")
    result = subprocess.run([str(exe), "example", "calsphere"], capture_output=True, text=True)
    assert result.returncode == 0 and "CALSPHERE 4A" in result.stdout


def test_plot_writes_png_and_refuses_overwrite(tmp_path: Path) -> None:
    pytest.importorskip("matplotlib")
    scenario = _short_scenario(tmp_path, stop="2020-02-29T21:14:00Z", step_s=10.0)
    out = tmp_path / "out.nc"
    assert runner.invoke(app, ["simulate", str(scenario), "-o", str(out)]).exit_code == 0
    fig = tmp_path / "fig.png"
    first = runner.invoke(app, ["plot", str(out), "-o", str(fig)])
    assert first.exit_code == 0, first.output
    assert fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    again = runner.invoke(app, ["plot", str(out), "-o", str(fig)])
    assert again.exit_code == 2 and "--force" in again.stderr
    other = tmp_path / "other.png"
    bad_kind = runner.invoke(app, ["plot", str(out), "-o", str(other), "--kind", "chian"])
    assert bad_kind.exit_code == 2 and "did you mean 'chain'" in bad_kind.stderr
    assert not other.exists()


def test_plot_rejects_a_file_that_is_not_a_dataset(tmp_path: Path) -> None:
    junk = tmp_path / "junk.nc"
    junk.write_text("not netcdf")
    result = runner.invoke(app, ["plot", str(junk), "-o", str(tmp_path / "f.png")])
    assert result.exit_code == 2 and "cannot read" in result.stderr


def test_stage_errors_name_the_scenario_file(tmp_path: Path) -> None:
    data = yaml.safe_load(example_text("calsphere"))
    data["time"].update(stop="2020-02-29T21:16:00Z", step_s=60.0)
    data["render"]["variant"] = "llvm_ad_foo"
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(data))
    result = runner.invoke(app, ["simulate", str(path), "-o", str(tmp_path / "o.nc")])
    assert result.exit_code == 2
    assert f"{path}: render.variant: render variant 'llvm_ad_foo' is not available" in result.stderr


CUBE_OBJ = """# a unit cube in two groups: the top face and the rest
v -0.5 -0.5 -0.5
v 0.5 -0.5 -0.5
v 0.5 0.5 -0.5
v -0.5 0.5 -0.5
v -0.5 -0.5 0.5
v 0.5 -0.5 0.5
v 0.5 0.5 0.5
v -0.5 0.5 0.5
g top
f 5 6 7 8
g sides
f 1 4 3 2
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
"""


def _mesh_scenario(tmp_path: Path, materials: dict[str, object]) -> Path:
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "cube.obj").write_text(CUBE_OBJ)
    data = yaml.safe_load(example_text("calsphere"))
    data["time"].update(start="2020-02-29T21:16:00Z", stop="2020-02-29T21:17:00Z", step_s=30.0)
    data["target"] = {"shape": {"mesh_file": "meshes/cube.obj"}, "materials": materials}
    data["render"]["resolution_px"] = 64
    path = tmp_path / "cube.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_mesh_target_relative_to_the_scenario_file(tmp_path: Path) -> None:
    lambert = {"bsdf": "lambertian", "reflectance": 0.5}
    scenario = _mesh_scenario(tmp_path, {"top": lambert, "sides": lambert})
    out = tmp_path / "cube.nc"
    # run from another folder: the mesh path is relative to the scenario file
    result = runner.invoke(app, ["simulate", str(scenario), "-o", str(out)])
    assert result.exit_code == 0, result.output
    intensity = xr.open_dataset(out)["intensity"].values
    assert np.all(intensity[np.isfinite(intensity)] >= 0) and np.nanmax(intensity) > 0


def test_material_for_a_missing_part_lists_the_parts(tmp_path: Path) -> None:
    lambert = {"bsdf": "lambertian", "reflectance": 0.5}
    scenario = _mesh_scenario(tmp_path, {"top": lambert, "side": lambert})
    out = tmp_path / "cube.nc"
    result = runner.invoke(app, ["simulate", str(scenario), "-o", str(out)])
    assert result.exit_code == 2
    assert "side" in result.stderr and "sides" in result.stderr and "top" in result.stderr
    assert not out.exists()


def test_without_libllvm_it_falls_back_with_a_one_line_notice(tmp_path: Path) -> None:
    # A fresh process in which no libLLVM 16-19 is found (as on a machine without libllvm19):
    # the run must succeed on the scalar/numpy path and say so in one line.
    scenario = _short_scenario(
        tmp_path, start="2020-02-29T21:16:00Z", stop="2020-02-29T21:17:00Z", step_s=30.0
    )
    code = (
        "import sys\n"
        "import speclight.render.variant as v\n"
        "v.find_libllvm = lambda: None\n"
        "from speclight.cli import main\n"
        f"sys.argv = ['speclight', 'simulate', {str(scenario)!r}, '-o', "
        f"{str(tmp_path / 'o.nc')!r}, '-q']\n"
        "main()\n"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    lines = [line for line in run.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("notice: no CUDA GPU and no libLLVM 16-19")
    assert xr.open_dataset(tmp_path / "o.nc").attrs["render_variant"] in ("numpy", "scalar_rgb")
