"""Progress of long stages (issue 14 item 11): shown on a terminal, silent otherwise."""

from __future__ import annotations

import io
import re

import pytest

import speclight
import speclight.progress as progress_module
from speclight.progress import shown, stage

#: six sunlit, observable epochs of the box-wing example (renders in both modes)
SHORT = {"render.resolution_px": 16, "time.stop": "2019-08-30T02:20:05Z"}
PATH = {**SHORT, "render.mode": "path", "render.samples_per_pixel": 4}


def _text(raw: str) -> str:
    return re.sub(r"\x1b\[[0-9;?]*[A-Za-z]", "", raw)  # without the terminal's control codes


class _Tty(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.fixture
def every_stage_reported(monkeypatch):  # type: ignore[no-untyped-def]
    monkeypatch.setattr(progress_module, "REPORT_AFTER_S", 0.0)  # also the quick ones


def test_stage_draws_on_a_terminal_and_reports_when_done(every_stage_reported) -> None:
    out = _Tty()
    with stage("rendering (path)", 4, file=out) as advance:
        advance(4)
    text = _text(out.getvalue())
    assert "rendering (path)" in text and "4/4" in text and "done rendering (path)" in text


def test_quick_stage_leaves_no_closing_line() -> None:
    out = _Tty()
    with stage("atmosphere (SPECTRL2)", file=out):
        pass
    assert "done" not in _text(out.getvalue())


def test_forced_stage_draws_on_any_stream(every_stage_reported) -> None:
    out = io.StringIO()
    with stage("atmosphere (6S)", force=True, file=out) as advance:
        advance(1)
    assert "done atmosphere (6S)" in _text(out.getvalue())


@pytest.mark.parametrize("enabled", [True, False])
def test_stage_is_silent_without_a_terminal(enabled: bool) -> None:
    out = io.StringIO()
    with stage("rendering (single)", 3, enabled=enabled, file=out) as advance:
        advance(3)
    assert out.getvalue() == ""
    assert not shown(enabled, file=out)
    assert not shown(False, force=True, file=_Tty())


@pytest.mark.parametrize(("overrides", "mode"), [(SHORT, "single"), (PATH, "path")])
def test_simulation_reports_every_long_stage(
    monkeypatch, capsys, every_stage_reported, overrides, mode
) -> None:
    # a terminal, as far as the stages can tell
    monkeypatch.setattr(progress_module, "shown", lambda enabled, **_: enabled)
    speclight.simulate("box-wing", overrides, progress=True)
    err = _text(capsys.readouterr().err)
    for label in ("orbit, attitude and geometry", f"rendering ({mode})", "atmosphere ("):
        assert f"done {label}" in err, err


def test_simulation_prints_nothing_without_a_terminal(capsys) -> None:
    speclight.simulate("box-wing", SHORT, progress=True)  # pytest's stderr is no terminal
    assert capsys.readouterr().err == ""
