"""Estimation commands on broken points and options that cannot finish: exit 2, one line naming
the flag and the numbers, no output; a run that passes writes finite numbers (issue 22)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from speclight.cli import app
from speclight.cli.flags import flag_names as _flag_names
from speclight.errors import InputError
from speclight.scenario import example_text

runner = CliRunner()


def test_core_parameter_names_become_flags() -> None:
    with pytest.raises(InputError) as err, _flag_names(n_phases="--phases", draws="--draws"):
        raise InputError("n_phases = 0 must be >= 1; give fewer n_phases", field="n_phases")
    assert err.value.field == "--phases"
    assert err.value.message == "--phases = 0 must be >= 1; give fewer --phases"
    # a plain word only where it is assigned: the prose around it stays
    with pytest.raises(InputError) as err, _flag_names(draws="--draws"):
        raise InputError("draws = 9 is more than a few draws", field="draws")
    assert err.value.message == "--draws = 9 is more than a few draws"
    with pytest.raises(InputError) as err, _flag_names(draws="--draws"):  # not mapped: as is
        raise InputError("x = 1", field="x")
    assert err.value.field == "x"


def _csv(path: Path, n: int = 120, huge: bool = False) -> Path:
    """One band of a 23 s light curve with sigmas, from 2020-02-29T21:16:00 UTC."""
    t = np.arange(n)
    rate = 1e5 * 10 ** (-0.4 * 0.3 * np.cos(2 * np.pi * t / 23.0))
    rate += np.random.default_rng(0).normal(0, np.sqrt(rate))
    if huge:
        rate[5] = 1e20  # below the reader's 1e30 s-1 ceiling: the periodogram's own check
    start = np.datetime64("2020-02-29T21:16:00", "s")
    rows = ["time,B,B_sigma"] + [
        f"{start + np.timedelta64(int(i), 's')}Z,{r:.6g},{np.sqrt(max(r, 1e5)):.6g}"
        for i, r in zip(t, rate, strict=True)
    ]
    path.write_text("\n".join(rows) + "\n")
    return path


@pytest.mark.filterwarnings("ignore::speclight.orbit.staleness.StaleInputWarning")
@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--min-period-s", "1e6", "--max-period-s", "1e7"], "--max-period-s = 1e+07 s is longer"),
        (["--draws", "1000000000"], "--draws = 1000000000 must be 1..10000"),
        (["--min-period-s", "1e-6"], "--min-period-s = 1e-06: the periodogram of 5.95e+08"),
        (["--seed", "-1"], "--seed = -1"),
        (["--bin-s", "1e9"], "--bin-s = 1e+09 s is not shorter than the 119 s"),
        (["--huge"], "rate 1e+20 s-1 is"),
        (["--scenario", "box-wing.yaml"], "below the horizon"),
    ],
)
def test_period_refuses_with_one_line(tmp_path: Path, args: list[str], words: str) -> None:
    data = _csv(tmp_path / "lc.csv", huge=args == ["--huge"])
    if args[0] == "--scenario":  # another satellite, site and night (2019-08-30)
        (tmp_path / "box-wing.yaml").write_text(example_text("box-wing"))
        args = ["--scenario", str(tmp_path / "box-wing.yaml")]
    out = tmp_path / "p.json"
    cmd = ["period", str(data), "-o", str(out), "--draws", "3"]
    result = runner.invoke(app, [*cmd, *[a for a in args if a != "--huge"]])
    assert result.exit_code == 2, result.output
    lines = [ln for ln in result.output.splitlines() if ln.startswith("error:")]
    assert len(lines) == 1 and words in lines[0], result.output
    assert "Traceback" not in result.output and not out.exists()


def test_period_in_a_range_is_finite(tmp_path: Path) -> None:
    data = _csv(tmp_path / "lc.csv")
    out = tmp_path / "p.json"
    args = ["--min-period-s", "30", "--max-period-s", "39", "--if-symmetric", "keep"]
    result = runner.invoke(app, ["period", str(data), "-o", str(out), "--draws", "3", *args])
    assert result.exit_code == 0, result.output
    summary = json.loads(out.read_text())  # strict JSON: NaN would not parse as a number
    assert 30 <= summary["photometric_period_s"] <= 39
    for key in ("false_alarm_probability", "best_power"):
        assert summary[key] is not None and math.isfinite(summary[key]), key
    # the 23 s signal is outside 30..39 s: no period is detected there, and it is said so
    # (issue 25: no confident detection of nothing); a detected one would be finite
    if summary["detected"]:
        for key in ("period_s", "period_std_s"):
            assert summary[key] is not None and math.isfinite(summary[key]), key
    else:
        assert summary["period_s"] is None and "no period detected" in summary["verdict"]
