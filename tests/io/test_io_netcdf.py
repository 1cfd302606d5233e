"""The dataset writer: atomic, never overwrites without force, CF attributes survive."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from speclight.errors import InputError
from speclight.io import write_dataset


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
