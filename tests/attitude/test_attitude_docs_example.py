"""The worked example of the attitude profiles in docs/scenario.md runs as written."""

from __future__ import annotations

import re
from pathlib import Path

DOC = Path(__file__).resolve().parents[2] / "docs" / "scenario.md"


def test_profile_example_runs(run_python) -> None:
    text = DOC.read_text()
    section = text.split("### Operational attitude profiles", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    assert len(blocks) == 1
    stdout = run_python(blocks[0])
    # the yaw-steering law the example shows: the Sun in the body x-z plane, on the +x side
    largest_y, smallest_x = re.search(
        r"largest \|sun_y\| (\S+), smallest sun_x (\S+)", stdout
    ).groups()
    assert float(largest_y) < 1e-12 and float(smallest_x) > 0.0
