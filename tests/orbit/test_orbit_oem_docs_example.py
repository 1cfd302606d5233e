"""The worked OEM example of docs/scenario.md (orbit section) runs as written."""

from __future__ import annotations

import re
from pathlib import Path

DOC = Path(__file__).resolve().parents[2] / "docs" / "scenario.md"


def test_oem_example_runs(run_python) -> None:
    section = DOC.read_text().split("## `orbit`", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    assert len(blocks) == 1
    stdout = run_python(blocks[0])
    # Hermite of SGP4 states at 60 s: < 0.5 m (tests/orbit/test_orbit_oem.py, TOL_SGP4_M)
    diff = float(re.search(r"largest range difference (\S+) m", stdout).group(1))
    assert diff < 0.5
