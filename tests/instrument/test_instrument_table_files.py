"""Bad table files (QE curve, band file): each is an InputError naming the file, never a crash.

Reproducers of the bad-input audit (issue 9): fuzz/0225 band file of binary garbage, 0230
band file of NaN values, 0239 QE file of binary garbage, 0240 QE file of NaN values (which
used to give NaN count rates with no flag).
"""

from __future__ import annotations

import os
import signal
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.instrument import band_response, spectral_curve
from speclight.instrument.tables import read_user_text

GRID_NM = np.arange(400.0, 701.0, 5.0)
#: The first bytes of the audit's garbage files (fuzz/0225/band.csv): 0xc8 is not UTF-8.
GARBAGE = bytes.fromhex("1e746b79c84295ebda3c6c5133f46f8860da135bf96ae44a")


def _qe(path: Path) -> object:
    return spectral_curve(str(path), GRID_NM)


def _band(path: Path) -> object:
    return band_response([str(path)], GRID_NM)


READERS: dict[str, Callable[[Path], object]] = {"qe": _qe, "band": _band}


@pytest.fixture
def no_hang() -> Iterator[None]:
    """Fail (instead of blocking the suite) if the reader opens a FIFO and waits on it."""

    def hung(signum: int, frame: object) -> None:
        raise TimeoutError("the reader blocked on a FIFO")

    old = signal.signal(signal.SIGALRM, hung)
    signal.alarm(5)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


@pytest.mark.parametrize("reader", READERS)
@pytest.mark.parametrize(
    ("content", "message"),
    [
        (GARBAGE, r"byte 0xc8 at line 1, .*is not UTF-8"),
        ("wavelength_nm,value\n450,0.5\n".encode("utf-16"), r"is UTF-16 text.*save it as UTF-8"),
        (b"wavelength_nm,value\n450,0.5\n500\x00,0.6\n", r"a NUL byte at line 3"),
        (b"wavelength_nm,value\n450,nan\n500,nan\n550,nan\n", r"line 2 .*'nan'.*not a finite"),
        (b"wavelength_nm,value\n450,0.5\n500,inf\n", r"line 3 .*'inf'.*not a finite"),
        (b"wavelength_nm,value\n450,0.5\n", r"at least 2 rows.*found 1 row\(s\) of 2"),
        (b"# nothing but a comment\n", r"at least 2 rows.*found no numeric row"),
    ],
    ids=["garbage", "utf16", "nul", "nan", "inf", "one-row", "empty"],
)
def test_bad_table_content_names_the_file(
    tmp_path: Path, reader: str, content: bytes, message: str
) -> None:
    f = tmp_path / "curve.csv"
    f.write_bytes(content)
    with pytest.raises(InputError, match=message) as err:
        READERS[reader](f)
    assert err.value.source == str(f)


@pytest.mark.parametrize("reader", READERS)
def test_paths_that_are_not_files_are_refused_without_blocking(
    tmp_path: Path, reader: str, no_hang: None
) -> None:
    folder = tmp_path / "curves.csv"
    folder.mkdir()
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    cases = [
        (folder, "is a folder"),
        (fifo, "not a regular file"),
        (tmp_path / "missing.csv", "does not exist"),
        (tmp_path / "missing.csv" / "below.csv", "does not exist"),
        (tmp_path / "nul\0byte.csv", "not a valid path"),
    ]
    if Path("/dev/zero").exists():
        cases.append((Path("/dev/zero"), "not a regular file"))
    for path, message in cases:
        with pytest.raises(InputError, match=message):
            READERS[reader](path)


def test_inline_curve_with_nan_is_refused() -> None:
    with pytest.raises(InputError, match="not finite"):
        spectral_curve(([400.0, 500.0, 600.0], [0.5, np.nan, 0.5]), GRID_NM)


def test_read_user_text_drops_a_byte_order_mark(tmp_path: Path) -> None:
    f = tmp_path / "bom.csv"
    f.write_bytes(b"\xef\xbb\xbfwavelength_nm,value\n")
    assert read_user_text(f, "instrument.bands") == "wavelength_nm,value\n"
