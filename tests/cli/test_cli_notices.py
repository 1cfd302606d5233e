"""The command line's notices are printed once per process (issue 22 item 9: `compare` printed
the Earth-orientation notice again for every site, and again before later errors)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import yaml

from speclight.orbit import iers_files
from speclight.scenario import example_text


def _late(when: np.datetime64) -> str:
    return str(np.datetime_as_string(when, unit="s")) + "Z"


def test_earth_orientation_notice_is_printed_once_per_process(tmp_path: Path) -> None:
    coverage = iers_files.finals_coverage(iers_files.finals_path())
    assert coverage is not None
    # a day past the table's last one (extrapolated UT1 and polar motion): every run warns
    start = np.datetime64(coverage.predicted_until, "s") + np.timedelta64(2, "D")
    scenario = yaml.safe_load(example_text("calsphere"))
    scenario["time"] = {"start": _late(start), "stop": _late(start + 60), "step_s": 10.0}
    scenario["render"]["resolution_px"] = 8
    (tmp_path / "late.yaml").write_text(yaml.safe_dump(scenario))
    # two sites, one simulation each: two notices of different counts (2 and 3 epochs)
    sites = {(48.7822, 9.1967, 355): (0, 30), (46.8772, 7.4652, 951): (0, 20, 40)}
    rows = [
        f"{_late(start + dt)},{lat},{lon},{alt},V,9.0,0.05"
        for (lat, lon, alt), offsets_s in sites.items()
        for dt in offsets_s
    ]
    header = "time,latitude_deg,longitude_deg,altitude_m,band,magnitude,magnitude_sigma"
    (tmp_path / "obs.csv").write_text("\n".join([header, *rows]) + "\n")
    done = subprocess.run(
        [sys.executable, "-m", "speclight", "compare", "late.yaml", "obs.csv", "-o", "c.nc"],
        cwd=tmp_path, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    # the TLE's target is not observable from either site then: compare simulates both
    # sites (the notices come from there), then refuses a comparison of nothing (exit 2)
    assert done.returncode == 2, done.stderr
    assert "none of the 5 observed epochs is usable" in done.stderr
    notices = [ln for ln in done.stderr.splitlines() if "Earth-orientation" in ln]
    assert len(notices) == 1, done.stderr
    assert notices[0].startswith("notice: 2 of 2 epochs")
    # the TLE's age notice, the same text for both sites, is printed once too
    assert len([ln for ln in done.stderr.splitlines() if "the TLE's epoch" in ln]) == 1
