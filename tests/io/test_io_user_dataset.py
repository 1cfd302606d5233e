"""Reading a NetCDF dataset a user names: every unusable file is an InputError, never a
traceback, and CF times are read as CF says.

References: the CF conventions (1.10, section 4.4: a time coordinate is a number with units
``<unit> since <epoch>``); the HDF5 file format specification (the signature ``\\x89HDF\\r\\n
\\x1a\\n`` at offset 0); the NetCDF classic format specification (files start with ``CDF``).
"""

from __future__ import annotations

import builtins
import errno
import os
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import xarray as xr

from speclight.errors import InputError
from speclight.io.user_dataset import read_user_dataset, values

T0 = np.datetime64("2020-02-29T21:16:00", "ns")


def _dataset(n: int = 4) -> xr.Dataset:
    t = T0 + np.arange(n) * np.timedelta64(2, "s")
    return xr.Dataset(
        {
            "count_rate": (("time", "band"), np.arange(2.0 * n).reshape(n, 2), {"units": "s-1"}),
            "phase_vector_body": (("time", "xyz"), np.tile([0.0, 0.0, 1.0], (n, 1))),
        },
        coords={"time": t, "band": ["B", "R"], "xyz": ["x", "y", "z"]},
        attrs={"scenario_yaml": "name: x"},
    )


def _write(ds: xr.Dataset, path: Path) -> Path:
    for var in ds.variables.values():
        var.encoding = {}
    ds.to_netcdf(path, engine="h5netcdf")
    return path


def _refusal(path: Path, **kwargs: Any) -> str:
    with pytest.raises(InputError) as info:
        read_user_dataset(path, "MEASURED", what="measurements", **kwargs)
    assert info.value.source == str(path) and info.value.field == "MEASURED"
    return info.value.message


def test_a_dataset_is_read_into_memory_with_only_the_variables_asked_for(tmp_path: Path) -> None:
    path = _write(_dataset(), tmp_path / "pass.nc")
    ds = read_user_dataset(path, "MEASURED", variables=["count_rate", "not_there"])
    assert list(ds.data_vars) == ["count_rate"]
    assert set(ds.coords) == {"time", "band", "xyz"} and ds.attrs["scenario_yaml"] == "name: x"
    path.unlink()  # nothing is read from the file any more
    np.testing.assert_array_equal(
        values(ds, "count_rate", ("band", "time"), "s", "F")[1], [1, 3, 5, 7]
    )


def test_cf_times_are_decoded_from_their_units(tmp_path: Path) -> None:
    ds = _dataset().assign_coords(time=("time", [0.0, 2.0, 4.0, 6.5]))
    ds["time"].attrs["units"] = "seconds since 2020-02-29T21:16:00"
    back = read_user_dataset(_write(ds, tmp_path / "cf.nc"), "MEASURED")
    # CF 1.10 section 4.4: value x units since epoch
    expected = T0 + np.array([0, 2000, 4000, 6500]) * np.timedelta64(1, "ms")
    np.testing.assert_array_equal(back["time"].values.astype("datetime64[ns]"), expected)


@pytest.mark.parametrize(
    ("content", "fragment"),
    [
        (b"", "it is not a NetCDF4 (HDF5) file; give a file written by `speclight simulate`"),
        (b"CDF\x01" + bytes(100), "it is NetCDF-3 (classic)"),
        (bytes(range(256)), "it is not a NetCDF4 (HDF5) file"),
        (b"\x89HDF\r\n\x1a\n" + bytes(range(256)) * 8, "the file is damaged (OSError"),
    ],
)
def test_bytes_that_are_not_netcdf4_are_refused(tmp_path: Path, content: bytes, fragment: str):
    path = tmp_path / "x.nc"
    path.write_bytes(content)
    message = _refusal(path)
    assert message.startswith("cannot read it as a NetCDF dataset: ") and fragment in message


# h5netcdf's File.__del__ of a file it failed to open raises; the command line silences that
@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_damage_anywhere_in_a_file_is_an_input_error_or_a_dataset(tmp_path: Path) -> None:
    """HDF5 reports damage as KeyError, RuntimeError, OSError or UnicodeDecodeError, at opening
    or at reading a variable (the issue's corrupted NetCDF); bytes that decode are data."""
    raw = _write(_dataset(40), tmp_path / "good.nc").read_bytes()
    rng = np.random.default_rng(7)
    outcomes = set()
    for k in range(60):
        spoilt = bytearray(raw)
        at = int(rng.integers(8, len(raw) - 32))
        spoilt[at : at + 32] = rng.bytes(32)
        path = tmp_path / f"bad{k}.nc"
        path.write_bytes(bytes(spoilt))
        try:
            read_user_dataset(path, "MEASURED")
            outcomes.add("read")
        except InputError as exc:
            outcomes.add(exc.message.split(":")[0])
    assert "cannot read it as a NetCDF dataset" in outcomes  # the property is not vacuous


@pytest.mark.parametrize(
    ("spoil", "fragment"),
    [
        (lambda ds: ds.assign(count_rate=ds["count_rate"].expand_dims(extra=2)),
         "count_rate is on the dimensions (extra, time, band); a speclight dataset has it on "
         "(time, band)"),
        (lambda ds: ds.rename({"time": "epoch"}),
         "count_rate is on the dimensions (epoch, band)"),
        (lambda ds: xr.Dataset({"temperature": ("epoch", np.arange(4.0))}),
         "no 'time' dimension (its dimensions: epoch)"),
        (lambda ds: ds.drop_vars("time"), "the 'time' dimension has no values"),
        (lambda ds: ds.assign_coords(time=np.arange(4.0)),
         "'time' holds float64 values with no units, not CF times"),
        (lambda ds: ds.assign_coords(time=np.arange(4)), "'time' holds int64 values"),
        (lambda ds: ds.assign(count_rate=ds["count_rate"].astype(str)),
         "count_rate holds <U3 values, not numbers"),
        (lambda ds: ds.isel(xyz=[0, 1]), "the dimension 'xyz' has 2 entries"),
    ],
)  # fmt: skip
def test_a_layout_other_than_speclight_s_is_refused_by_name(tmp_path: Path, spoil, fragment):
    message = _refusal(_write(spoil(_dataset()), tmp_path / "odd.nc"))
    assert fragment in message, message


def test_missing_times_are_refused(tmp_path: Path) -> None:
    ds = _dataset()
    t = ds["time"].values.copy()
    t[2] = np.datetime64("NaT")
    assert "'time' is missing (NaT) at index 2" in _refusal(
        _write(ds.assign_coords(time=t), tmp_path / "nat.nc")
    )


def test_paths_that_cannot_be_read(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    assert "no such file" in _refusal(tmp_path / "none.nc")
    assert "it is a folder" in _refusal(tmp_path)
    loop = tmp_path / "loop.nc"
    loop.symlink_to(tmp_path / "back.nc")
    (tmp_path / "back.nc").symlink_to(loop)
    assert "a loop of symbolic links" in _refusal(loop)
    # mode 000 as a user who may not read it (tests run as root, who may): the open refused
    locked = _write(_dataset(), tmp_path / "locked.nc")
    real_open = builtins.open

    def refuse(file: Any, *args: Any, **kwargs: Any) -> Any:
        if Path(file) == locked:
            raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(file))
        return real_open(file, *args, **kwargs)

    monkeypatch.setattr(builtins, "open", refuse)
    assert "permission denied" in _refusal(locked)
