"""The command line's outputs: claimed before the work, never lost, nothing left behind."""

from __future__ import annotations

import errno
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml
from typer.testing import CliRunner

from speclight.cli import app
from speclight.io.output import lock_path
from speclight.scenario import example_text

runner = CliRunner()


def _geometry_scenario(
    tmp_path: Path, stop: str = "2020-02-29T21:13:10Z", name: str = "scenario.yaml"
) -> Path:
    """The calsphere pass without a target: geometry only, quick to run."""
    data = yaml.safe_load(example_text("calsphere"))
    for section in ("target", "instrument", "atmosphere", "render", "illumination", "spectrum"):
        data.pop(section)
    data["time"].update(stop=stop, step_s=5.0)
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


@contextmanager
def _claimed_by_another_process(output: Path) -> Iterator[subprocess.Popen[str]]:
    code = (
        "import sys\n"
        "from speclight.io.output import OutputClaim\n"
        "with OutputClaim(sys.argv[1]):\n"
        "    print('held', flush=True)\n"
        "    sys.stdin.read()\n"
    )
    holder = subprocess.Popen(
        [sys.executable, "-c", code, str(output)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout is not None and holder.stdout.readline() == "held\n"
        yield holder
    finally:
        holder.kill()
        holder.communicate()


def test_a_second_run_to_the_same_output_fails_at_once(tmp_path: Path) -> None:
    scenario = _geometry_scenario(tmp_path)
    out = tmp_path / "out.nc"
    with _claimed_by_another_process(out) as first:
        for force in ([], ["--force"]):
            second = runner.invoke(app, ["simulate", str(scenario), "-o", str(out), *force])
            assert second.exit_code == 2
            assert f"is being written by another speclight run (PID {first.pid})" in second.stderr
    assert not out.exists()


def test_output_equal_to_the_scenario_is_refused(tmp_path: Path) -> None:
    scenario = _geometry_scenario(tmp_path)
    text = scenario.read_text()
    (tmp_path / "sub").mkdir()
    (tmp_path / "link.yaml").symlink_to(scenario)
    for spelling in (tmp_path / "sub" / ".." / "scenario.yaml", tmp_path / "link.yaml"):
        result = runner.invoke(app, ["simulate", str(scenario), "-o", str(spelling), "--force"])
        assert result.exit_code == 2
        assert f"{spelling} is the scenario file {scenario}" in result.stderr
    assert scenario.read_text() == text


@pytest.mark.parametrize(
    ("output", "message"),
    [
        ("", "--output: the file name is empty"),
        ("{tmp}", "--output: {tmp} names a folder"),
        ("{tmp}/nope/out.nc", "--output: folder {tmp}/nope of {tmp}/nope/out.nc does not exist"),
    ],
)
def test_a_bad_output_name_is_reported_before_any_work(
    tmp_path: Path, output: str, message: str
) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("time: {step_s: 0}\n")  # would fail too, but the output is checked first
    result = runner.invoke(app, ["simulate", str(bad), "-o", output.format(tmp=tmp_path)])
    assert result.exit_code == 2
    assert result.stderr.startswith(f"error: {message.format(tmp=tmp_path)}")
    assert len(result.stderr.splitlines()) == 1


def test_a_full_disk_is_one_line_and_exit_1(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    scenario = _geometry_scenario(tmp_path)
    out = tmp_path / "out.nc"
    real_write = os.write

    def disk_full_for_the_output(fd: int, data: bytes) -> int:
        if len(data) > 100:  # not the lock's PID
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real_write(fd, data)

    monkeypatch.setattr(os, "write", disk_full_for_the_output)
    result = runner.invoke(app, ["simulate", str(scenario), "-o", str(out)])
    monkeypatch.undo()
    assert result.exit_code == 1
    assert result.stderr.splitlines() == [
        f"error: cannot write {out}: No space left on device; nothing was written"
    ]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scenario.yaml"]


def _start_long_run(tmp_path: Path) -> subprocess.Popen[str]:
    """A subprocess simulating a 2-hour window, once it holds its output's lock."""
    scenario = _geometry_scenario(tmp_path, stop="2020-02-29T23:13:00Z")
    out = tmp_path / "out.nc"
    proc = subprocess.Popen(
        [sys.executable, "-m", "speclight.cli", "simulate", str(scenario), "-o", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 20.0
    while not lock_path(out).exists():
        assert proc.poll() is None and time.monotonic() < deadline, "the run did not start"
        time.sleep(0.01)
    return proc


@pytest.mark.parametrize(
    ("signum", "code", "line"),
    [
        (signal.SIGINT, 130, "error: interrupted"),
        (signal.SIGTERM, 143, "error: terminated by SIGTERM"),
        (signal.SIGHUP, 129, "error: terminated by SIGHUP"),
    ],
)
def test_a_signal_ends_the_run_in_one_line_leaving_nothing(
    tmp_path: Path, signum: int, code: int, line: str
) -> None:
    proc = _start_long_run(tmp_path)
    proc.send_signal(signum)
    _, stderr = proc.communicate(timeout=30)
    assert (proc.returncode, stderr.splitlines()) == (code, [line]), stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scenario.yaml"]


def test_the_next_run_removes_what_a_killed_run_left(tmp_path: Path) -> None:
    proc = _start_long_run(tmp_path)
    proc.kill()
    proc.communicate()
    killed_temp = tmp_path / f".out.nc.speclight-{proc.pid}-0123abcd.tmp"
    killed_temp.write_bytes(b"half a dataset")  # as a kill during the write leaves it
    short = _geometry_scenario(tmp_path, name="short.yaml")
    other = tmp_path / "other.nc"
    result = runner.invoke(app, ["simulate", str(short), "-o", str(other)])
    assert result.exit_code == 0, result.output
    assert xr.open_dataset(other).sizes["time"] == 3
    assert sorted(p.name for p in tmp_path.iterdir()) == ["other.nc", "scenario.yaml", "short.yaml"]


def test_plot_refuses_to_overwrite_its_dataset(tmp_path: Path) -> None:
    data = tmp_path / "pass.nc"
    data.write_bytes(b"a dataset")
    for dataset, output in ((data, data), (tmp_path / "fig-chain.png", tmp_path / "fig.png")):
        dataset.write_bytes(b"a dataset")
        result = runner.invoke(app, ["plot", str(dataset), "-o", str(output), "--force"])
        assert result.exit_code == 2, result.output
        assert "dataset" in result.stderr and "choose another name" in result.stderr
        assert dataset.read_bytes() == b"a dataset"


def test_plot_to_a_figure_another_run_is_writing_fails_at_once(tmp_path: Path) -> None:
    data = tmp_path / "pass.nc"
    data.write_bytes(b"a dataset")
    fig = tmp_path / "fig.png"
    with _claimed_by_another_process(fig) as first:
        result = runner.invoke(app, ["plot", str(data), "-o", str(fig)])
    assert result.exit_code == 2
    assert f"being written by another speclight run (PID {first.pid})" in result.stderr


def test_a_full_disk_when_the_lock_is_written_is_one_line_and_exit_1(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    scenario = _geometry_scenario(tmp_path)
    out = tmp_path / "out.nc"

    def disk_full(fd: int, data: bytes) -> int:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "write", disk_full)
    result = runner.invoke(app, ["simulate", str(scenario), "-o", str(out)])
    monkeypatch.undo()
    assert result.exit_code == 1
    assert result.stderr.splitlines() == [
        f"error: cannot write {out}: No space left on device (its lock file in {tmp_path}); "
        "nothing was written"
    ]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scenario.yaml"]


def test_plot_on_a_full_disk_is_one_line_and_exit_1(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from speclight.plot import figures

    data = tmp_path / "pass.nc"
    ran = runner.invoke(app, ["simulate", str(_geometry_scenario(tmp_path)), "-o", str(data)])
    assert ran.exit_code == 0, ran.output

    def full_device(path: Path) -> int:  # /dev/full: every write fails with ENOSPC
        return os.open("/dev/full", os.O_WRONLY)

    monkeypatch.setattr(figures, "create_new_file", full_device)
    result = runner.invoke(app, ["plot", str(data), "-o", str(tmp_path / "fig.png")])
    assert result.exit_code == 1, result.output
    assert result.stderr.splitlines() == [
        f"error: cannot write {tmp_path / 'fig.png'}: No space left on device; no figure was "
        "written"
    ]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pass.nc", "scenario.yaml"]


def _period_csv(tmp_path: Path) -> Path:
    """60 epochs of a 7 s sinusoid in one band: enough for `speclight period`."""
    t = np.arange(60)
    rate = 1000.0 * (1.0 + 0.3 * np.sin(2 * np.pi * t / 7.0))
    start = np.datetime64("2020-02-29T21:16:00", "s")
    rows = [f"{start + np.timedelta64(int(k), 's')}Z,{r:.3f}" for k, r in zip(t, rate, strict=True)]
    path = tmp_path / "lc.csv"
    path.write_text("time,B\n" + "\n".join(rows) + "\n")
    return path


def test_a_signal_while_the_figure_draws_leaves_nothing_and_the_rerun_works(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from speclight.plot import period_figure

    args = ["period", str(_period_csv(tmp_path)), "-o", str(tmp_path / "p.json")]
    args += ["--plot", str(tmp_path / "p.png"), "--draws", "2"]

    def interrupted(*args: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(period_figure, "period_figure", interrupted)
    result = runner.invoke(app, args)
    assert (result.exit_code, result.stderr.splitlines()) == (130, ["error: interrupted"])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["lc.csv"]
    monkeypatch.undo()
    rerun = runner.invoke(app, args)  # no --force needed: nothing was left
    assert rerun.exit_code == 0, rerun.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["lc.csv", "p.json", "p.png"]


def test_a_figure_that_cannot_be_written_takes_its_output_back(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from speclight.io.output import OutputClaim, OutputWriteError

    real_write = OutputClaim.write

    def no_room_for_figures(self: OutputClaim, data: bytes) -> Path:
        if self.path.suffix == ".png":
            raise OutputWriteError(f"cannot write {self.output}: No space left on device")
        return real_write(self, data)

    monkeypatch.setattr(OutputClaim, "write", no_room_for_figures)
    args = ["period", str(_period_csv(tmp_path)), "-o", str(tmp_path / "p.json")]
    result = runner.invoke(app, [*args, "--plot", str(tmp_path / "p.png"), "--draws", "2"])
    assert result.exit_code == 1, result.output
    assert "p.png: No space left on device" in result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["lc.csv"]
