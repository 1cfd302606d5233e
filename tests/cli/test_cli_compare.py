"""``speclight compare`` on the command line: outputs, the printed statistics, exit codes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr
import yaml
from typer.testing import CliRunner

from speclight.cli import app
from speclight.scenario import example_text

ROWS = """# latitude_deg: 48.7822
# longitude_deg: 9.1967
# altitude_m: 355
time,magnitude,magnitude_sigma,band
2020-02-29T21:16:00Z,8.0,0.05,V
2020-02-29T21:16:30Z,8.1,0.05,V
2020-02-29T21:13:30Z,8.1,0.05,V
"""


def _inputs(tmp_path: Path) -> tuple[Path, Path]:
    data = yaml.safe_load(example_text("calsphere"))
    data["render"]["resolution_px"] = 64
    data["instrument"]["noise"] = None
    scenario = tmp_path / "calsphere.yaml"
    scenario.write_text(yaml.safe_dump(data, sort_keys=False))
    obs = tmp_path / "obs.csv"
    obs.write_text(ROWS)
    return scenario, obs


def test_compare_writes_the_dataset_and_figure_and_prints_statistics(tmp_path) -> None:
    scenario, obs = _inputs(tmp_path)
    out, fig = tmp_path / "cmp.nc", tmp_path / "cmp.png"
    args = ["compare", str(scenario), str(obs), "-o", str(out), "--plot", str(fig)]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    assert "over 2 observations" in result.output and "by phase angle" in result.output
    assert fig.stat().st_size > 0
    with xr.open_dataset(out) as ds:
        assert ds.sizes["obs"] == 3
        # the third row is in the Earth's shadow: kept, NaN, flagged
        assert np.isnan(ds["magnitude_simulated"].values[2]) and ds["flags"].values[2] & 4
        r = ds["residual"].values[:2]
        assert ds.attrs["residual_rms_mag"] == np.sqrt(np.mean(r**2))
    again = CliRunner().invoke(app, args)  # no overwrite without --force
    assert again.exit_code == 2 and "exists" in again.output


def test_bad_observations_exit_2_and_leave_nothing(tmp_path) -> None:
    scenario, obs = _inputs(tmp_path)
    obs.write_text(ROWS.replace("8.1,0.05,V", "8.1,0.05,W"))
    out = tmp_path / "cmp.nc"
    result = CliRunner().invoke(app, ["compare", str(scenario), str(obs), "-o", str(out)])
    assert result.exit_code == 2
    assert "line 6, column 'band': 'W' is neither a band of the scenario" in result.output
    assert not out.exists()
