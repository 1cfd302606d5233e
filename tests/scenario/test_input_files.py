"""Reading the files a scenario names: every unusable file is an InputError, none hangs."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from speclight.errors import InputError
from speclight.input_files import read_user_text


def _refusal(path: Path | str, **kwargs: int) -> str:
    with pytest.raises(InputError) as exc:
        read_user_text(path, "orbit.tle_file", what="TLE file", **kwargs)
    msg = str(exc.value)
    assert msg.startswith(f"{path}: orbit.tle_file: cannot read TLE file: ")
    return msg


def test_utf8_text_is_read_with_bom_removed_and_line_ends_unified(tmp_path: Path) -> None:
    path = tmp_path / "a.txt"
    path.write_bytes(b"\xef\xbb\xbfname: Stra\xc3\x9fe\r\nx\ry\n")
    assert read_user_text(path) == "name: Straße\nx\ny\n"


def test_missing_file_folder_and_file_used_as_folder(tmp_path: Path) -> None:
    assert "no such file" in _refusal(tmp_path / "nope.tle")
    assert "it is a folder" in _refusal(tmp_path)
    (tmp_path / "f.tle").write_text("x")
    assert "a part of the path is a file" in _refusal(tmp_path / "f.tle" / "x.tle")


def test_fifo_is_refused_without_opening_it(tmp_path: Path) -> None:
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)  # opening it for reading would block until a writer comes
    assert "it is a FIFO (named pipe), not a regular file" in _refusal(fifo)


@pytest.mark.skipif(not Path("/dev/zero").exists(), reason="no /dev/zero")
def test_endless_device_is_refused() -> None:
    assert "it is a character device, not a regular file" in _refusal("/dev/zero")


def test_file_above_the_size_limit(tmp_path: Path) -> None:
    path = tmp_path / "big.tle"
    path.write_text("1" * 101)
    assert "it is 101 bytes, above the limit of 100 bytes" in _refusal(path, max_bytes=100)
    assert read_user_text(path, max_bytes=101) == "1" * 101


@pytest.mark.parametrize(
    ("data", "fragment"),
    [
        # Latin-1 'ä' (0xe4) in a satellite name line (fuzz/0068)
        (b"Kugel\n1 0136\xe4", "byte 0xe4 at line 2, column 7 (byte 12) is not UTF-8"),
        ("name: x".encode("utf-16"), "it is UTF-16 text (byte-order mark ff fe)"),
        ("name: x".encode("utf-16-be"), "a NUL byte at line 1, column 1 (byte 0)"),
        # the first of the bad bytes is named (fuzz/0360 has a NUL after byte 0xc8)
        (b"\x1etky\xc8B\x95\x00", "byte 0xc8 at line 1, column 5 (byte 4) is not UTF-8"),
        (b"\xef\xbb\xbfab\n\xff", "byte 0xff at line 2, column 1 (byte 6) is not UTF-8"),
    ],
)
def test_bytes_that_are_not_utf8_say_where(tmp_path: Path, data: bytes, fragment: str) -> None:
    path = tmp_path / "bad.tle"
    path.write_bytes(data)
    msg = _refusal(path)
    assert fragment in msg and "save it as UTF-8" in msg
