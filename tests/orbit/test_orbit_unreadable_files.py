"""Orbit files that cannot be read are InputErrors naming the file and the scenario field.

Reproducers (bad-input audit of issue 9, ``fuzz/``): a missing TLE/CPF/ephemeris file
(0059, 0063, 0075, 0099, 0104), a folder (0060, 0076, 0105), binary garbage (0061, 0077,
0106), ``/dev/zero`` (0072, a MemoryError before) and a FIFO (0073, a hang before).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from speclight.cli import app
from speclight.errors import InputError
from speclight.orbit import read_cpf, read_ephemeris_csv, read_tles
from speclight.scenario import example_text

READERS: dict[str, tuple[Callable[[Path], object], str]] = {
    "tle": (read_tles, "orbit.tle_file: cannot read TLE file"),
    "cpf": (read_cpf, "orbit.cpf_file: cannot read CPF file"),
    "ephemeris": (read_ephemeris_csv, "orbit.ephemeris_file: cannot read ephemeris file"),
}
#: The first bytes of the audit's 2,048-byte random file (fuzz/0061-tle-file-binary-garbage).
GARBAGE = bytes.fromhex("1e746b79c84295ebda3c6c5133f46f8860da135bf96ae44ad3da9182560c20a5")


def _bad_path(tmp_path: Path, kind: str) -> Path:
    if kind == "missing":
        return tmp_path / "nope" / ".." / "x.orbit"
    if kind == "folder":
        return tmp_path
    if kind == "fifo":
        os.mkfifo(tmp_path / "fifo")  # opening it would wait for a writer for ever
        return tmp_path / "fifo"
    if kind == "device":
        return Path("/dev/zero")  # endless: read_text() ran out of memory
    (tmp_path / "garbage").write_bytes(GARBAGE)
    return tmp_path / "garbage"


@pytest.mark.parametrize(
    ("kind", "fragment"),
    [
        ("missing", "no such file"),
        ("folder", "it is a folder"),
        ("fifo", "it is a FIFO (named pipe), not a regular file"),
        ("device", "it is a character device, not a regular file"),
        ("binary", "byte 0xc8 at line 1, column 5 (byte 4) is not UTF-8"),
    ],
)
@pytest.mark.parametrize("reader", sorted(READERS))
def test_unreadable_orbit_file_is_an_input_error(
    tmp_path: Path, reader: str, kind: str, fragment: str
) -> None:
    if kind == "device" and not Path("/dev/zero").exists():
        pytest.skip("no /dev/zero")
    read, field = READERS[reader]
    path = _bad_path(tmp_path, kind)
    with pytest.raises(InputError) as exc:
        read(path)
    assert str(exc.value).startswith(f"{path}: {field}: {fragment}")


def test_cli_exits_2_with_one_line_for_a_fifo_tle_file(tmp_path: Path) -> None:
    # fuzz/0073: the run hung on open() until killed after 60 s
    data = yaml.safe_load(example_text("lcs1"))
    data["orbit"] = {"tle_file": "fifo", "norad_id": 1361}
    os.mkfifo(tmp_path / "fifo")
    scenario = tmp_path / "s.yaml"
    scenario.write_text(yaml.safe_dump(data))
    result = CliRunner().invoke(app, ["simulate", str(scenario), "-o", str(tmp_path / "o.nc")])
    assert result.exit_code == 2
    assert result.stderr == (
        f"error: {tmp_path / 'fifo'}: orbit.tle_file: cannot read TLE file: it is a FIFO (named "
        "pipe), not a regular file; give the path of a file\n"
    )
