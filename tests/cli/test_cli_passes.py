"""``speclight passes``: the table, the CSV and JSON files, and exit 2 for bad input.

The events themselves are checked against skyfield in tests/orbit/test_orbit_passes.py; here
the files must carry the same passes as the Python function, in the documented layout
(docs/passes.md).
"""

from __future__ import annotations

import csv
import json
from datetime import UTC, datetime
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from speclight.cli import app
from speclight.scenario import example_text, load_example
from speclight.simulation.pass_search import scenario_passes
from speclight.simulation.pass_table import COLUMNS, utc_text

runner = CliRunner()
WINDOW = ["--start", "2020-02-29T18:00:00Z", "--end", "2020-03-01T12:00:00Z"]


def _scenario(tmp_path: Path, **changes: object) -> Path:
    data = yaml.safe_load(example_text("calsphere"))
    data.update(changes)
    path = tmp_path / "calsphere.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_csv_and_json_hold_the_passes(tmp_path: Path) -> None:
    scenario = _scenario(tmp_path)
    expected = scenario_passes(
        load_example("calsphere"),
        datetime(2020, 2, 29, 18, tzinfo=UTC),
        datetime(2020, 3, 1, 12, tzinfo=UTC),
    ).passes
    out_csv, out_json = tmp_path / "p.csv", tmp_path / "p.json"
    result = runner.invoke(app, ["passes", str(scenario), *WINDOW, "-o", str(out_csv)])
    assert result.exit_code == 0, result.output
    assert "passes of calsphere-4a-pass" in result.stdout and f"wrote {out_csv}" in result.stdout
    lines = out_csv.read_text().splitlines()
    assert "# max_sun_elevation_deg: -6.0" in lines
    rows = list(csv.DictReader(ln for ln in lines if not ln.startswith("#")))
    assert tuple(rows[0]) == COLUMNS and len(rows) == len(expected) == 5
    for row, p in zip(rows, expected, strict=True):
        assert row["rise_utc"] == utc_text(p.rise_utc)
        assert row["culmination_utc"] == utc_text(p.culmination_utc)
        assert abs(float(row["max_elevation_deg"]) - p.max_elevation_deg) <= 5e-4  # 3 decimals
        assert row["observable"] == ";".join(
            f"{utc_text(a)}/{utc_text(b)}" for a, b in p.observable
        )
    result = runner.invoke(app, ["passes", str(scenario), *WINDOW, "-o", str(out_json)])
    assert result.exit_code == 0, result.output
    data = json.loads(out_json.read_text())
    assert data["min_elevation_deg"] == 10.0 and data["max_sun_elevation_deg"] == -6.0
    assert [q["set_utc"] for q in data["passes"]] == [utc_text(p.set_utc) for p in expected]
    assert [q["sunlit"] for q in data["passes"]] == [
        [[utc_text(a), utc_text(b)] for a, b in p.sunlit] for p in expected
    ]
    # the two daytime passes are sunlit in a bright sky: nothing observable
    assert [q["observable_s"] > 0 for q in data["passes"]] == [True, True, True, False, False]


def test_without_options_the_scenarios_window_is_searched(tmp_path: Path) -> None:
    # the example's 8 minutes start inside a pass: it rises before the window
    result = runner.invoke(app, ["passes", str(_scenario(tmp_path))])
    assert result.exit_code == 0, result.output
    assert "(start)" in result.stdout


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["--start", "yesterday"], "--start = 'yesterday' is not an ISO 8601 time"),
        (["--start", "2020-03-01T00:00Z", "--end", "2020-02-29T00:00Z"], "before it starts"),
        (["--start", "2020-01-01T00:00Z", "--end", "2020-06-01T00:00Z"], "at most 60 days"),
        (["--start", "2060-01-01T00:00Z", "--end", "2060-01-02T00:00Z"], "JPL DE421"),
        (["-o", "passes.txt"], "CSV or JSON"),
    ],
)
def test_bad_options_exit_2(tmp_path: Path, arguments: list[str], message: str) -> None:
    result = runner.invoke(app, ["passes", str(_scenario(tmp_path)), *arguments])
    assert result.exit_code == 2, result.output
    assert message in result.stderr and "Traceback" not in result.output


def test_a_scenario_without_an_orbit_exits_2(tmp_path: Path) -> None:
    scenario = _scenario(tmp_path, orbit={"observed": True})
    result = runner.invoke(app, ["passes", str(scenario)])
    assert result.exit_code == 2, result.output
    assert "orbit.observed" in result.stderr


def test_an_existing_file_needs_force(tmp_path: Path) -> None:
    out = tmp_path / "p.csv"
    out.write_text("keep")
    result = runner.invoke(app, ["passes", str(_scenario(tmp_path)), "-o", str(out)])
    assert result.exit_code == 2 and out.read_text() == "keep"
    result = runner.invoke(app, ["passes", str(_scenario(tmp_path)), "-o", str(out), "--force"])
    assert result.exit_code == 0 and out.read_text().startswith("# scenario: calsphere-4a-pass")
