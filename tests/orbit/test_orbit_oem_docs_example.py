"""The worked OEM example of docs/scenario.md (orbit section) runs as written."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

DOC = Path(__file__).resolve().parents[2] / "docs" / "scenario.md"


def test_oem_example_runs(tmp_path: Path) -> None:
    section = DOC.read_text().split("## `orbit`", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    assert len(blocks) == 1
    run = subprocess.run(
        [sys.executable], input=blocks[0], cwd=tmp_path, capture_output=True, text=True,
        timeout=300,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr
    # Hermite of SGP4 states at 60 s: < 0.5 m (tests/orbit/test_orbit_oem.py, TOL_SGP4_M)
    diff = float(re.search(r"largest range difference (\S+) m", run.stdout).group(1))
    assert diff < 0.5
