"""Every option's help text reaches ``--help`` whole: typer renders help with rich markup,
where a unit in brackets ("[s]", "[sr-1]") is a markup tag and vanishes unless escaped
("\\[s]"). The test renders each command's help and looks for each text in it."""

from __future__ import annotations

import re

import pytest
import typer
from typer.testing import CliRunner

from speclight.cli import app

COMMAND = typer.main.get_command(app)  # a group: its commands by name
COMMANDS = COMMAND.commands  # type: ignore[attr-defined]


def _flat(text: str) -> str:
    """Help output without the panels' borders and line breaks."""
    return " ".join(re.sub(r"[│╭╮╰╯─]", " ", text).split())


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_every_option_help_is_shown_whole(name: str) -> None:
    result = CliRunner().invoke(app, [name, "--help"], terminal_width=200)
    assert result.exit_code == 0, result.output
    shown = _flat(result.output)
    for param in COMMANDS[name].params:
        text = getattr(param, "help", None)
        if text:
            assert _flat(text.replace("\\[", "[")) in shown, (name, param.name, text)
