"""docs/real-satellites.md's worked example runs as written (its shell block, in an empty
folder), and the files it names appear."""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

DOC = Path(__file__).resolve().parents[2] / "docs" / "real-satellites.md"


def test_real_satellites_example_runs(tmp_path):
    bin_dir = Path(sys.executable).parent
    if not (bin_dir / "speclight").exists():
        pytest.skip("speclight console script not installed in this environment")
    blocks = re.findall(r"```bash\n(.*?)```", DOC.read_text(), flags=re.S)
    assert blocks, "no shell block in docs/real-satellites.md"
    env = {**os.environ, "PATH": f"{bin_dir}{os.pathsep}{os.environ['PATH']}"}
    for code in blocks:
        run = subprocess.run(
            ["bash", "-euo", "pipefail", "-c", code],
            cwd=tmp_path,
            env=env,
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert run.returncode == 0, f"block failed:\n{code}\n{run.stdout}\n{run.stderr}"
    for name in ("starlink.yaml", "starlink.nc", "starlink.png"):
        assert (tmp_path / name).stat().st_size > 0, name
