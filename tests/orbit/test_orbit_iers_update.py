"""`speclight update-data` and the choice of the Earth-orientation / leap-second table.

Never touches the network: tables are installed from local files (``--from``) or ``file://``
addresses. The test tables are the shipped ``finals2000A.all`` extended by rows written in
the IERS column format (checked below against every row of the shipped file), so where a
run's UT1-UTC comes from can be told by its value.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from speclight.cli import app
from speclight.orbit import iers_files, staleness, timescale
from speclight.scenario import example_text

runner = CliRunner()
#: UT1-UTC written in the extension rows [s]: within 0.9 s of the shipped table's last value,
#: so skyfield sees no leap second between them.
DUT1_EXTENSION_S = 0.0500000
EXTENSION_DAYS = 400
MJD0 = np.datetime64("1858-11-17", "D")


def _row(mjd: int, dut1_s: float, x: float = 0.1, y: float = 0.3, flag: str = "P") -> str:
    """One row of finals2000A.all (readme.finals2000A: columns 1-78 of the Bulletin A part)."""
    day = (MJD0 + np.timedelta64(mjd, "D")).astype(object)
    return (
        f"{day.year % 100:2d}{day.month:2d}{day.day:2d} {mjd:8.2f} {flag} "
        f"{x:9.6f}{0.001:9.6f} {y:9.6f}{0.001:9.6f}  {flag}{dut1_s:10.7f}{0.0001:10.7f}"
    )


def _shipped_rows() -> list[str]:
    lines = iers_files.shipped_finals_path().read_text().splitlines()
    return [ln for ln in lines if len(ln) >= 68 and ln[58:68].strip()]


def _extended_table(tmp_path: Path) -> tuple[Path, np.datetime64]:
    rows = _shipped_rows()
    last = int(float(rows[-1][7:15]))
    rows += [_row(last + k, DUT1_EXTENSION_S) for k in range(1, EXTENSION_DAYS + 1)]
    path = tmp_path / "finals2000A.all"
    path.write_text("\n".join(rows) + "\n")
    return path, MJD0 + np.timedelta64(last + EXTENSION_DAYS, "D")


@pytest.fixture
def data_dir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    folder = tmp_path / "user-data"
    monkeypatch.setenv("SPECLIGHT_DATA_DIR", str(folder))
    timescale.reload_tables()
    yield folder
    timescale.reload_tables()  # the environment is restored after this: rebuilt lazily


def test_the_row_format_is_that_of_the_shipped_table() -> None:
    # every 97th row of the shipped file, rebuilt from its values: the same columns
    for line in _shipped_rows()[::97]:
        mjd, x, y = int(float(line[7:15])), float(line[18:27]), float(line[37:46])
        ours = _row(mjd, float(line[58:68]), x, y, flag=line[16])
        fields = (slice(0, 27), slice(36, 46), slice(55, 68))  # date MJD flag x, y, flag UT1
        assert [ours[f] for f in fields] == [line[f] for f in fields]


def test_update_from_a_file_is_used_by_runs(data_dir: Path, tmp_path: Path) -> None:
    table, end = _extended_table(tmp_path)
    when = end - np.timedelta64(30, "D")  # inside the extension, past the shipped table
    ts = timescale.load_timescale()
    day = when.astype(object)
    before = float(ts.utc(day.year, day.month, day.day).dut1)
    assert abs(before - DUT1_EXTENSION_S) > 0.01  # the shipped table extrapolates
    assert staleness.tables_notice(np.array([when], dtype="datetime64[ns]")) is not None

    previous = os.umask(0o027)
    try:
        result = runner.invoke(app, ["update-data", "--from", str(table)])
    finally:
        os.umask(previous)
    assert result.exit_code == 0, result.output
    assert f"predicted (and leap seconds known) until {end}" in result.stdout
    installed = data_dir / "iers" / "finals2000A.all"
    assert installed.read_text() == table.read_text()
    assert installed.stat().st_mode & 0o777 == 0o640  # like any new file under umask 027

    coverage = timescale.data_coverage()
    assert coverage["eop_predicted_until"] == str(end)
    assert str(installed) in coverage["eop_table"]
    ts = timescale.load_timescale()
    # the run's UT1-UTC is the value in the installed file (constant over the extension)
    assert float(ts.utc(day.year, day.month, day.day).dut1) == pytest.approx(
        DUT1_EXTENSION_S, abs=1e-6
    )
    assert staleness.tables_notice(np.array([when], dtype="datetime64[ns]")) is None


def test_update_from_a_file_address_takes_the_download_path(data_dir: Path, tmp_path: Path):
    table, end = _extended_table(tmp_path)
    result = runner.invoke(app, ["update-data", "--url", table.as_uri()])
    assert result.exit_code == 0, result.output
    assert timescale.data_coverage()["eop_predicted_until"] == str(end)


def test_an_older_table_is_installed_but_the_shipped_one_stays_in_use(
    data_dir: Path, tmp_path: Path
) -> None:
    shipped_end = timescale.data_coverage()["eop_predicted_until"]
    older = tmp_path / "finals2000A.all"
    older.write_text("\n".join(_shipped_rows()[:-400]) + "\n")
    result = runner.invoke(app, ["update-data", "--from", str(older)])
    assert result.exit_code == 0, result.output
    assert "reaches further and stays in use" in result.stderr
    assert timescale.data_coverage()["eop_predicted_until"] == shipped_end
    assert iers_files.finals_path() == iers_files.shipped_finals_path()


def test_tables_that_are_not_complete_finals_files_are_refused(
    data_dir: Path, tmp_path: Path
) -> None:
    daily = tmp_path / "finals.daily"  # the last 90 days and predictions only
    daily.write_text("\n".join(_shipped_rows()[-90:]) + "\n")
    result = runner.invoke(app, ["update-data", "--from", str(daily)])
    assert result.exit_code == 2
    assert "whole history" in result.stderr and "finals.daily" in result.stderr
    junk = tmp_path / "junk.txt"
    junk.write_text("MJD,UT1-UTC\n60000,0.1\n")
    result = runner.invoke(app, ["update-data", "--from", str(junk)])
    assert result.exit_code == 2 and "not an IERS finals2000A.all table" in result.stderr
    result = runner.invoke(app, ["update-data", "--url", (tmp_path / "none.all").as_uri()])
    assert result.exit_code == 1 and "cannot download" in result.stderr
    assert not data_dir.exists() or not any(data_dir.rglob("*"))


def test_a_table_cut_in_the_middle_of_a_line_is_not_installed(
    data_dir: Path, tmp_path: Path
) -> None:
    table, _ = _extended_table(tmp_path)
    text = table.read_text()
    cut = tmp_path / "cut.all"
    # cut inside the last row's UT1-UTC (columns 59-68): '0.05000' of '0.0500000' still parses
    cut.write_text(text[: text.rstrip("\n").rfind("\n") + 1 + 65])
    result = runner.invoke(app, ["update-data", "--from", str(cut)])
    assert result.exit_code == 2, result.output
    assert "ends in the middle of line" in result.stderr and "cut short" in result.stderr
    assert not data_dir.exists() or not any(data_dir.rglob("*"))
    # a complete table without the final line end is a table
    whole = tmp_path / "whole.all"
    whole.write_text(text.rstrip("\n"))
    assert runner.invoke(app, ["update-data", "--from", str(whole)]).exit_code == 0


def test_nothing_is_downloaded_when_tables_are_loaded(
    data_dir: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import urllib.request

    import skyfield.iokit

    def refuse(*args: object, **kwargs: object) -> None:
        raise AssertionError("network access")

    monkeypatch.setattr(skyfield.iokit, "download", refuse)
    monkeypatch.setattr(urllib.request, "urlopen", refuse)
    timescale.reload_tables()
    ts = timescale.load_timescale()
    assert ts.utc(2026, 12, 1).tt > 0
    assert timescale.data_coverage()["eop_predicted_until"]


def test_a_run_past_the_tables_with_an_old_tle_gives_one_notice_each(tmp_path: Path) -> None:
    scenario = yaml.safe_load(example_text("calsphere"))  # TLE epoch 2020-02-27
    scenario.pop("target")  # geometry only: quick
    scenario["time"] = {"start": "2035-06-01T00:00:00Z", "stop": "2035-06-01T00:00:20Z",
                        "step_s": 10.0}  # fmt: skip
    path = tmp_path / "late.yaml"
    path.write_text(yaml.safe_dump(scenario))
    env = {**os.environ, "SPECLIGHT_DATA_DIR": str(tmp_path / "no-update")}
    out = tmp_path / "o.nc"
    run = subprocess.run(
        [sys.executable, "-m", "speclight.cli", "simulate", str(path), "-o", str(out)],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )
    assert run.returncode == 0, run.stderr
    notices = [ln for ln in run.stderr.splitlines() if ln.startswith("notice: ")]
    assert len([n for n in notices if "Earth-orientation and leap-second table" in n]) == 1
    assert len([n for n in notices if "the TLE's epoch 2020-02-27" in n]) == 1
    assert "speclight update-data" in run.stderr
