"""Fixtures shared by every test folder."""

from __future__ import annotations

import signal
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest

# A suite started in the background of a non-interactive shell (`pytest ... &`, some CI
# runners) inherits SIGINT ignored, and so does every child it starts: the tests that send
# Ctrl-C to a run would then see it ignored, as `nohup` asks. The suite takes SIGINT back;
# its children start with the default disposition (Python then raises KeyboardInterrupt).
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


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
