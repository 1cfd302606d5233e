"""The worked example of docs/compare.md runs as written."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

DOC = Path(__file__).resolve().parents[2] / "docs" / "compare.md"


def test_compare_worked_example_runs(tmp_path: Path) -> None:
    bin_dir = Path(sys.executable).parent
    if not (bin_dir / "speclight").exists():
        pytest.skip("speclight console script not installed in this environment")
    env = {**os.environ, "PATH": f"{bin_dir}{os.pathsep}{os.environ['PATH']}"}
    section = DOC.read_text().split("## Worked example", 1)[1]
    blocks = re.findall(r"```bash\n(.*?)```", section, flags=re.S)
    assert len(blocks) == 1
    run = subprocess.run(
        ["bash", "-euo", "pipefail", "-c", blocks[0]], cwd=tmp_path, env=env,
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert "over 5 observations" in run.stdout and (tmp_path / "cmp.png").exists()
    with xr.open_dataset(tmp_path / "cmp.nc") as ds:
        # what the page says: the first row is in the Earth's shadow, NaN and flagged
        assert np.isnan(ds["magnitude_simulated"].values[0])
        assert ds["flags"].values[0] & 4
        assert np.isfinite(ds["residual"].values[1:]).all()
