"""A bad record of an orbit table ends as the ``orbit_failed`` flag of its epochs.

The pipeline's geometry stage turns the readers' ok mask into ``FLAG_ORBIT_FAILED``
(``speclight.simulation.geometry_stage``); these tests run that stage on a tiny window.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml

import speclight
from speclight import schema as v
from speclight.scenario import example_text, parse_scenario
from speclight.simulation.geometry_stage import scenario_geometry

SAMPLE_CPF = Path(speclight.__file__).parent / "data/cpf/lcs1_20201127_speclight_sgp4.cpf"
HOLE_CSV = Path(__file__).parent / "data" / "lcs1_itrf_6h_hole.csv"


def _flags(
    tmp_path: Path, orbit: dict[str, str], start: str, stop: str, step_s: float
) -> np.ndarray:
    data = yaml.safe_load(example_text("lcs1"))
    data["orbit"] = orbit
    data["time"] = {"start": start, "stop": stop, "step_s": step_s}
    loaded = parse_scenario(yaml.safe_dump(data), source="s.yaml", base_dir=tmp_path)
    return scenario_geometry(loaded).flags


def test_nan_cpf_record_is_flagged_orbit_failed(tmp_path: Path) -> None:
    # issue 9 item 8: the NaN record at 17:36 made NaN positions flagged only as
    # below_min_elevation, as if the target were known and low.
    lines = SAMPLE_CPF.read_text().splitlines()
    i = next(i for i, ln in enumerate(lines) if ln.startswith("10 0 59180  63360.000000"))
    lines[i] = "10 0 59180  63360.000000  0  nan  nan  nan"
    (tmp_path / "nan.cpf").write_text("\n".join(lines) + "\n")
    flags = _flags(
        tmp_path, {"cpf_file": "nan.cpf"}, "2020-11-27T17:31:00Z", "2020-11-27T17:41:00Z", 120.0
    )
    failed = (flags & v.FLAG_ORBIT_FAILED) != 0
    # records every 240 s: the epochs between 17:32 and 17:40 lose their position (epochs
    # off the records, as light time moves the target's epoch ~10 ms earlier)
    assert failed.tolist() == [False, True, True, True, True, False]


def test_epochs_in_an_ephemeris_hole_are_flagged_orbit_failed(tmp_path: Path) -> None:
    # ephemeris-gap/gap_hole.yaml: 17:40 to 23:50 every 600 s over a table without rows
    # from 17:48 to 00:00; only 17:40 is outside the hole.
    flags = _flags(
        tmp_path,
        {"ephemeris_file": str(HOLE_CSV)},
        "2020-11-27T17:40:00Z",
        "2020-11-27T23:50:00Z",
        600.0,
    )
    failed = (flags & v.FLAG_ORBIT_FAILED) != 0
    assert not failed[0] and failed[1:].all()
