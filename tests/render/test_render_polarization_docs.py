"""The worked example of docs/polarization.md runs as written and prints what the page says."""

from __future__ import annotations

import re
from pathlib import Path

DOC = Path(__file__).resolve().parents[2] / "docs" / "polarization.md"


def test_polarization_page_runs_as_written(tmp_path: Path, run_python) -> None:
    text = DOC.read_text()
    stdout = run_python("\n".join(re.findall(r"```python\n(.*?)```", text, flags=re.S)))
    shown = re.findall(r"```text\n(.*?)```", text, flags=re.S)
    assert shown[0].strip() == stdout.split("Stokes frame")[0].strip()
    assert shown[1].strip() == "Stokes frame" + stdout.split("Stokes frame")[1].rstrip()
    # the single mode's DoLP of a microfacet sphere is the Fresnel ratio at the half angle
    for line in stdout.splitlines()[1:13]:
        _, _, dolp, fresnel, _ = line.split()
        assert dolp == fresnel, line
    assert (tmp_path / "calsphere-polarization.png").stat().st_size > 10_000
