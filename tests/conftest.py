"""Fixtures shared by every test folder."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest


@pytest.fixture
def run_python(tmp_path: Path) -> Callable[[str], str]:
    """Run code (a documentation page's example) in a fresh interpreter in ``tmp_path`` as a
    user would paste it; fail with its stderr unless it succeeds; return its stdout."""

    def run(code: str) -> str:
        done = subprocess.run(
            [sys.executable], input=code, cwd=tmp_path, capture_output=True, text=True,
            timeout=300,
        )  # fmt: skip
        assert done.returncode == 0, done.stderr
        return done.stdout

    return run
