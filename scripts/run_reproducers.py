"""Run the robustness reproducers of ../shared/repro through the CLI and tabulate the outcomes.

    python scripts/run_reproducers.py [REPRO_DIR] [--timeout S]

Each case's scenario is copied with its input files into a temporary folder and run as
``speclight simulate scenario.yaml -o out.nc``; the outcome is ``ok`` (exit 0), ``input``
(exit 2, one ``error:`` line, no traceback) or a failure: ``internal`` (exit 1), ``signal``,
``hang`` (past the timeout), or ``traceback`` (a traceback printed with exit 0 or 2). Exit 1
if any case failed. The suite has a regression test for each class; this is the check that
every reproducer of the audit is covered.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def run_case(folder: Path, scenario: Path, timeout_s: float) -> tuple[str, float, str]:
    with tempfile.TemporaryDirectory(prefix="speclight-repro-") as tmp:
        for f in folder.iterdir():
            if f.suffix == ".IS_A_FIFO":  # the audit's marker: "mkfifo this name to reproduce"
                os.mkfifo(Path(tmp) / f.stem)
            elif f.is_file() and f.suffix not in (".log", ".txt"):
                shutil.copy(f, Path(tmp) / f.name)
        if "adir" in scenario.read_text():  # the audit's "file is a directory" cases
            (Path(tmp) / "adir").mkdir()
        cmd = [sys.executable, "-m", "speclight.cli", "simulate", scenario.name, "-o", "out.nc"]
        t0 = time.perf_counter()
        try:
            out = subprocess.run(cmd, cwd=tmp, capture_output=True, text=True, timeout=timeout_s)
        except subprocess.TimeoutExpired:
            return "hang", time.perf_counter() - t0, ""
        wall = time.perf_counter() - t0
        text = out.stdout + out.stderr
        last = text.strip().splitlines()[-1] if text.strip() else ""
        if "Traceback" in text:
            return "traceback", wall, last
        if out.returncode == 0:
            return "ok", wall, last
        if out.returncode == 2:
            return "input", wall, last
        if out.returncode < 0:
            return "signal", wall, last
        return "internal", wall, last


def main() -> int:
    here = Path(__file__).resolve().parent.parent
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("repro", nargs="?", type=Path, default=here.parent / "shared" / "repro")
    parser.add_argument("--timeout", type=float, default=120.0)
    args = parser.parse_args()
    cases = [
        (d, d / "scenario.yaml") for d in sorted((args.repro / "fuzz").iterdir()) if d.is_dir()
    ]
    for sub in ("plate-crash", "ephemeris-gap"):
        cases += [(args.repro / sub, f) for f in sorted((args.repro / sub).glob("*.yaml"))]
    failed = 0
    for folder, scenario in cases:
        outcome, wall, last = run_case(folder, scenario, args.timeout)
        bad = outcome not in ("ok", "input")
        failed += bad
        name = folder.name if scenario.name == "scenario.yaml" else f"{folder.name}/{scenario.name}"
        print(f"{'FAIL' if bad else 'pass'}  {outcome:9s} {wall:6.1f} s  {name}  {last[:110]}")
    print(f"{len(cases) - failed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
