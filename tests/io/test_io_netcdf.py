"""The dataset writer: atomic, never overwrites without force, CF attributes survive."""

from __future__ import annotations

import errno
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from speclight.errors import InputError
from speclight.io import write_dataset
from speclight.io.output import OutputWriteError


def _dataset() -> xr.Dataset:
    t = np.array(["2020-01-01T00:00:00", "2020-01-01T00:00:01.5"], dtype="datetime64[ns]")
    return xr.Dataset(
        {"range": ("time", [7.0e6, 7.1e6], {"units": "m", "long_name": "range"})},
        coords={"time": t},
    )


def test_round_trip_keeps_times_to_the_microsecond_and_attrs(tmp_path: Path) -> None:
    out = write_dataset(_dataset(), tmp_path / "a.nc")
    back = xr.open_dataset(out)
    np.testing.assert_array_equal(back["time"].values, _dataset()["time"].values)
    assert back["range"].attrs["units"] == "m"


def test_refuses_overwrite_and_leaves_no_temporary(tmp_path: Path) -> None:
    out = tmp_path / "a.nc"
    out.write_text("keep")
    with pytest.raises(InputError, match="--force"):
        write_dataset(_dataset(), out)
    assert out.read_text() == "keep"
    write_dataset(_dataset(), out, force=True)
    assert xr.open_dataset(out)["range"].size == 2
    assert [p.name for p in tmp_path.iterdir()] == ["a.nc"]


def test_failed_write_leaves_nothing(tmp_path: Path) -> None:
    bad = _dataset()
    bad["oops"] = ("time", np.array([object(), object()]))  # not serialisable
    with pytest.raises((TypeError, ValueError)):
        write_dataset(bad, tmp_path / "b.nc")
    assert list(tmp_path.iterdir()) == []


def test_missing_folder_is_an_input_error(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="does not exist"):
        write_dataset(_dataset(), tmp_path / "nope" / "a.nc")


def test_output_gets_the_usual_permissions(tmp_path: Path) -> None:
    previous = os.umask(0o022)
    try:
        out = write_dataset(_dataset(), tmp_path / "a.nc")
    finally:
        os.umask(previous)
    assert out.stat().st_mode & 0o777 == 0o644


def test_full_disk_is_one_clear_error_and_leaves_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    real_write = os.write
    calls = []

    def disk_fills_up(fd: int, data: bytes) -> int:
        calls.append(fd)
        if len(calls) == 1:
            return real_write(fd, bytes(data)[:100])  # the first bytes fit
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "write", disk_fills_up)
    with pytest.raises(OutputWriteError, match=r"a\.nc: No space left on device; nothing was"):
        write_dataset(_dataset(), tmp_path / "a.nc")
    monkeypatch.undo()
    assert len(calls) >= 2  # the lock's PID, then the data until the disk was full
    assert list(tmp_path.iterdir()) == []


SERIALISE_SLOWLY = """
import sys
import numpy as np
import xarray as xr
from speclight.io import write_dataset

rng = np.random.default_rng(0)
ds = xr.Dataset({"v": (("t", "w"), rng.random((1500, 1500)))})  # about 0.4 s to compress
print("writing", flush=True)
try:
    write_dataset(ds, sys.argv[1])
except KeyboardInterrupt:
    sys.exit(130)
print("wrote")
"""


def test_ctrl_c_while_hdf5_writes_is_not_lost(tmp_path: Path) -> None:
    # h5py drops a KeyboardInterrupt raised in its callbacks ("Exception ignored in ..."):
    # the write went on and the program ended normally. The interrupt must reach the caller.
    out = tmp_path / "big.nc"
    proc = subprocess.Popen(
        [sys.executable, "-c", SERIALISE_SLOWLY, str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert proc.stdout is not None and proc.stdout.readline() == "writing\n"
    time.sleep(0.15)
    proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=30)
    assert proc.returncode == 130, stdout + stderr
    assert "Exception ignored" not in stderr and "wrote" not in stdout
    assert list(tmp_path.iterdir()) == []
