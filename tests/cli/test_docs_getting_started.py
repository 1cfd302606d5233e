"""The new-user path runs as written: README's first-run block, then docs/getting-started.md
(its shell and Python blocks, in order), all in one folder, as a user following both would."""

from __future__ import annotations

import hashlib
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "getting-started.md"
README = ROOT / "README.md"


def _blocks(path: Path) -> list[tuple[str, str]]:
    return re.findall(r"```(bash|python)\n(.*?)```", path.read_text(), flags=re.S)


def _run(lang: str, code: str, cwd: Path, env: dict[str, str]) -> None:
    cmd = ["bash", "-euo", "pipefail", "-c", code] if lang == "bash" else [sys.executable]
    run = subprocess.run(
        cmd,
        input=None if lang == "bash" else code,
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 0, f"{lang} block failed:\n{code}\n{run.stdout}\n{run.stderr}"


def _files(folder: Path) -> dict[str, str]:
    return {
        p.name: hashlib.sha256(p.read_bytes()).hexdigest()
        for p in folder.iterdir()
        if p.is_file() and not p.is_symlink()
    }


def test_readme_then_getting_started_run_as_written(tmp_path: Path) -> None:
    bin_dir = Path(sys.executable).parent
    if not (bin_dir / "speclight").exists():
        pytest.skip("speclight console script not installed in this environment")
    env = {**os.environ, "PATH": f"{bin_dir}{os.pathsep}{os.environ['PATH']}"}
    # README's commands run from the repository root, where the set-up made .venv
    (tmp_path / ".venv").symlink_to(bin_dir.parent, target_is_directory=True)

    readme = [(lang, code) for lang, code in _blocks(README) if "speclight example" in code]
    assert len(readme) == 1, "README's first-run block (speclight example ...) not found"
    _run(*readme[0], tmp_path, env)
    from_readme = _files(tmp_path)
    assert from_readme, "README's block wrote nothing"

    blocks = _blocks(DOC)
    assert len(blocks) >= 3
    for lang, code in blocks:
        if "scripts/setup.sh" in code:
            continue  # the set-up itself is what CI runs before the tests
        _run(lang, code, tmp_path, env)
    after = _files(tmp_path)
    assert (tmp_path / "my.nc").exists() and (tmp_path / "my.png").exists()
    # following both in order: getting-started neither overwrites nor trips over README's files
    assert {name: after[name] for name in from_readme} == from_readme


def test_readme_runs_python_from_the_virtual_environment() -> None:
    # A bare `python` is the system one, which has neither xarray nor speclight.
    for lang, code in _blocks(README):
        if lang == "bash":
            for line in code.splitlines():
                command = line.split("#")[0].strip()
                assert not re.match(r"^(python3?|pip3?)\b", command), line


def test_getting_started_names_every_built_in_scenario() -> None:
    # issue 22 item 9: the page's comment listed 3 of the 9 examples
    from speclight.scenario import example_names

    text = DOC.read_text()
    names = example_names()
    assert f"lists the {len(names)} built-in scenarios" in text
    assert [n for n in names if f"`{n}`" not in text] == []
