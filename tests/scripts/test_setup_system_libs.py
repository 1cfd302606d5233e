"""scripts/setup.sh finds installed system libraries and runs apt-get only for missing ones.

The detection (scripts/system_libs.sh) is run in bash against fake library folders, a fake
``ldconfig`` and a fake ``apt-get`` on PATH, so nothing on this machine is read or changed.
The folders Debian's packages fill are those of ``dpkg -L libllvm19 libgfortran5`` (bookworm):
``/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1`` (plus the ``libLLVM-19.so`` link) and
``libgfortran.so.5`` -> ``libgfortran.so.5.0.0``; ``ldconfig -p`` lists libLLVM 19 only by its
SONAME, ``libLLVM.so.19.1``.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

from speclight.render import variant

ROOT = Path(__file__).resolve().parents[2]
LIBS = ROOT / "scripts" / "system_libs.sh"

pytestmark = pytest.mark.skipif(shutil.which("bash") is None, reason="needs bash")

# `ldconfig -p` of a Debian 12 machine with libllvm19 and libgfortran5 installed (excerpt).
LINKER_CACHE = """540 libs found in cache `/etc/ld.so.cache'
\tlibgfortran.so.5 (libc6,x86-64) => /lib/x86_64-linux-gnu/libgfortran.so.5
\tlibLLVM.so.19.1 (libc6,x86-64) => /lib/x86_64-linux-gnu/libLLVM.so.19.1
\tlibLLVM-15.so.1 (libc6,x86-64) => /lib/x86_64-linux-gnu/libLLVM-15.so.1
"""


def _tools(tmp_path: Path, linker_cache: str = "") -> Path:
    """Fake ``ldconfig`` (printing ``linker_cache``), ``id`` (root) and ``apt-get`` (logging)."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir(exist_ok=True)
    (tmp_path / "cache.txt").write_text(linker_cache)
    scripts = {
        "ldconfig": f'cat "{tmp_path / "cache.txt"}"',
        "id": "echo 0",
        "apt-get": f'echo "$*" >>"{tmp_path / "apt.log"}"',
    }
    for name, body in scripts.items():
        path = bin_dir / name
        path.write_text(f"#!/bin/sh\n{body}\n")
        path.chmod(0o755)
    return bin_dir


def _bash(tmp_path: Path, libs: Path, command: str, linker_cache: str = "") -> str:
    bin_dir = _tools(tmp_path, linker_cache)
    env = {k: v for k, v in os.environ.items() if k != "DRJIT_LIBLLVM_PATH"}
    env.update(PATH=f"{bin_dir}{os.pathsep}{env['PATH']}", SPECLIGHT_LIB_DIRS=str(libs))
    run = subprocess.run(
        ["bash", "-c", f'set -euo pipefail; source "{LIBS}"; {command}'],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert run.returncode == 0, run.stderr
    return run.stdout


def _libs(tmp_path: Path, *names: str) -> Path:
    libs = tmp_path / "lib"
    libs.mkdir()
    for name in names:
        (libs / name).parent.mkdir(parents=True, exist_ok=True)
        (libs / name).write_bytes(b"\x7fELF")
    return libs


def _apt_calls(tmp_path: Path) -> list[str]:
    log = tmp_path / "apt.log"
    return log.read_text().splitlines() if log.exists() else []


def test_installed_debian_packages_are_found_and_apt_is_not_run(tmp_path: Path) -> None:
    libs = _libs(tmp_path, "libLLVM.so.19.1", "libgfortran.so.5")  # no libLLVM-19.so link
    assert _bash(tmp_path, libs, "missing_system_libs") == ""
    _bash(tmp_path, libs, "install_system_libs")
    assert _apt_calls(tmp_path) == []


def test_the_linker_cache_alone_finds_them(tmp_path: Path) -> None:
    libs = _libs(tmp_path)
    assert _bash(tmp_path, libs, "missing_system_libs", LINKER_CACHE) == ""


def test_missing_libraries_are_installed_with_apt(tmp_path: Path) -> None:
    libs = _libs(tmp_path, "libLLVM-15.so", "libLLVM-15.so.1")  # 15 crashes Mitsuba: unusable
    cache = "\tlibLLVM-15.so.1 (libc6,x86-64) => /lib/x86_64-linux-gnu/libLLVM-15.so.1\n"
    assert _bash(tmp_path, libs, "missing_system_libs", cache).split() == [
        "libllvm19",
        "libgfortran5",
    ]
    _bash(tmp_path, libs, "install_system_libs", cache)
    calls = _apt_calls(tmp_path)
    assert calls[-1].split()[-2:] == ["libllvm19", "libgfortran5"]
    assert calls[-1].split()[:2] == ["install", "-y"]


@pytest.mark.parametrize(
    "name",
    [
        "libLLVM-19.so",
        "libLLVM.so.19.1",
        "libLLVM.so.18",
        "libLLVM-16.dylib",
        "llvm-17/lib/libLLVM-17.so",
        "libLLVM-15.so",
        "libLLVM.so.1",
        "libLLVM-20.so",
    ],
)
def test_setup_finds_libllvm_as_speclight_does(
    tmp_path: Path, name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    libs = _libs(tmp_path, name)
    monkeypatch.setattr(variant, "_LLVM_DIRS", (str(libs),))
    monkeypatch.delenv("DRJIT_LIBLLVM_PATH", raising=False)
    found_by_speclight = variant.find_libllvm() is not None
    found_by_setup = _bash(tmp_path, libs, "have_libllvm && echo yes || echo no").strip()
    assert found_by_setup == ("yes" if found_by_speclight else "no")


def test_setup_script_sources_the_detection_and_parses() -> None:
    assert subprocess.run(["bash", "-n", str(ROOT / "scripts" / "setup.sh")]).returncode == 0
    text = (ROOT / "scripts" / "setup.sh").read_text()
    assert "source scripts/system_libs.sh" in text and "install_system_libs" in text
