"""``speclight fit`` on the command line (SPEC sections 2 and 5): FIT.json, figure, refusals.

Reference for the fitted numbers: the albedo the measurements were simulated with (0.73,
from a scenario that starts at 0.4), to the issue's 2 %.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from speclight.cli import app
from speclight.io.netcdf import write_dataset
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate

runner = CliRunner()
SPEC_KEYS = {"bands", "roughness", "rms_percent_of_mean", "rms_percent_of_total", "n_epochs",
             "method", "converged", "message"}  # fmt: skip
BAND_KEYS = {"albedo", "albedo_std", "scale", "rms_percent_of_mean"}


def _scenario(reflectance: float) -> dict:
    d = yaml.safe_load(example_text("calsphere"))
    d["time"].update(start="2020-02-29T21:15:00Z", stop="2020-02-29T21:17:00Z", step_s=2.0)
    d["render"]["resolution_px"] = 32
    d["target"]["materials"]["body"]["reflectance"] = reflectance
    d["instrument"]["bands"] = d["instrument"]["bands"][:3]  # B, G, R
    return d


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("fit")
    truth = simulate(parse_scenario(yaml.safe_dump(_scenario(0.73)), source="truth")).dataset
    nc = write_dataset(truth, folder / "measured.nc")
    rate = truth["count_rate_measured"].transpose("time", "band").values
    times = np.datetime_as_string(truth["time"].values, unit="s")
    lines = ["# simulated, albedo 0.73", "time,B,G,R,R_sigma"]
    for t, (b, g, r) in zip(times, rate, strict=True):
        lines.append(f"{t}Z,{b:.6g},{g:.6g},{r:.6g},{np.sqrt(max(r, 1.0)):.6g}")
    csv = folder / "measured.csv"
    csv.write_text("\n".join(lines) + "\n")
    scenario = folder / "start.yaml"
    scenario.write_text(yaml.safe_dump(_scenario(0.4)))
    return {"nc": nc, "csv": csv, "scenario": scenario, "folder": folder}


@pytest.mark.parametrize("kind", ["nc", "csv"])
def test_fit_writes_the_spec_json_and_the_figure(files: dict[str, Path], kind: str) -> None:
    out = files["folder"] / f"fit-{kind}.json"
    fig = files["folder"] / f"fit-{kind}.png"
    args = ["fit", str(files["scenario"]), str(files[kind]), "-o", str(out), "--plot", str(fig)]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    data = json.loads(out.read_text())
    assert set(data) >= SPEC_KEYS
    assert data["converged"] is True and data["roughness"] == {}
    assert list(data["bands"]) == ["B", "G", "R"]
    for band in data["bands"].values():
        assert set(band) >= BAND_KEYS
        assert band["albedo"] == pytest.approx(0.73, rel=0.02)
    assert fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert f"wrote {out}" in result.stdout


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--free", "albedo,colour"], "--free"),
        (["--bin-s", "-1"], "--bin-s"),
        (["--plot", "fig.txt"], "--plot"),
        (["--method", "newton"], "--method = 'newton': give one of slsqp, gradient"),
        (["--clip-sigma", "-3"], "--clip-sigma"),
    ],
)
def test_bad_options_exit_2_and_write_nothing(
    files: dict[str, Path], extra: list[str], message: str
) -> None:
    out = files["folder"] / "bad.json"
    args = ["fit", str(files["scenario"]), str(files["nc"]), "-o", str(out), *extra]
    result = runner.invoke(app, args)
    assert result.exit_code == 2
    assert message in result.stderr
    assert not out.exists()


def test_band_mismatch_and_missing_file_exit_2(files: dict[str, Path]) -> None:
    d = _scenario(0.4)
    d["instrument"]["bands"][0]["name"] = "U"
    other = files["folder"] / "other-bands.yaml"
    other.write_text(yaml.safe_dump(d))
    out = files["folder"] / "mismatch.json"
    result = runner.invoke(app, ["fit", str(other), str(files["csv"]), "-o", str(out)])
    assert result.exit_code == 2
    assert "band 'U' of the scenario is not in the measurements" in result.stderr
    assert not out.exists()
    missing = files["folder"] / "nothere.csv"
    result = runner.invoke(app, ["fit", str(files["scenario"]), str(missing), "-o", str(out)])
    assert result.exit_code == 2
    assert "nothere.csv" in result.stderr
    assert not out.exists()


def test_existing_output_needs_force_and_output_cannot_be_an_input(files: dict[str, Path]) -> None:
    out = files["folder"] / "exists.json"
    out.write_text("keep")
    args = ["fit", str(files["scenario"]), str(files["nc"]), "-o", str(out)]
    result = runner.invoke(app, args)
    assert result.exit_code == 2
    assert "--force" in result.stderr
    assert out.read_text() == "keep"
    result = runner.invoke(app, ["fit", str(files["scenario"]), str(files["csv"]), "-o",
                                 str(files["csv"]), "--force"])  # fmt: skip
    assert result.exit_code == 2
    assert files["csv"].read_text().startswith("# simulated")
