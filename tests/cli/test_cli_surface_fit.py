"""``speclight fit SCENARIO OBSERVATIONS --free brdf`` end to end (docs/surface-fit.md): the
output file and figure, the lines printed, and exit code 2 for what it refuses."""

from __future__ import annotations

import json
import sys
from pathlib import Path

from typer.testing import CliRunner

from speclight.cli import app

sys.path.insert(0, str(Path(__file__).parents[1] / "estimate"))
from surface_fit_data import FAR_START, TRUTH, write_observations, write_scenario


def test_fit_brdf_end_to_end(tmp_path: Path) -> None:
    obs = tmp_path / "obs.csv"
    write_observations(obs)
    start = write_scenario(tmp_path / "start.yaml", FAR_START)
    out, fig = tmp_path / "surfaces.json", tmp_path / "surfaces.png"
    args = ["fit", str(start), str(obs), "--free", "brdf", "-o", str(out), "--plot", str(fig)]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    assert "bus_nadir (phong): kd 0.3" in result.output
    assert "cross-validated RMS" in result.output
    assert fig.stat().st_size > 0
    s = json.loads(out.read_text())
    kd = s["surfaces"]["bus_nadir"]["parameters"]["kd"]
    assert abs(kd["value"] - TRUTH["bus_nadir"]["kd"]) < 3 * kd["std"]
    assert set(s) >= {"surfaces", "fit", "start", "cross_validation", "converged", "message"}
    # a second file that is not OBSERVATIONS, and a light-curve option: exit 2, one line
    bad = CliRunner().invoke(app, ["fit", str(start), str(start), "--free", "brdf", "-o",
                                   str(tmp_path / "x.json")])  # fmt: skip
    assert bad.exit_code == 2, bad.output
    binned = CliRunner().invoke(app, [*args[:4], "brdf", "--bin-s", "3", "-o",
                                      str(tmp_path / "y.json")])  # fmt: skip
    assert binned.exit_code == 2 and "--bin-s" in binned.output
