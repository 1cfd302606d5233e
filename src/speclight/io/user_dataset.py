"""Safe reading of a NetCDF dataset a user names: MEASURED of the estimation commands and the
DATASET of ``speclight plot``.

:func:`read_user_dataset` turns every way such a file can be unusable into an
:class:`~speclight.errors.InputError` that names the file and the argument, before any
computation sees it:

* the path: as :func:`speclight.input_files.check_user_file` (missing, a folder, a FIFO or
  device, a loop of symbolic links, permission denied);
* the bytes: not HDF5 (a NetCDF-3 "classic" file is named as such), or damaged. HDF5 reports
  damage as ``KeyError``, ``RuntimeError``, ``OSError`` or ``UnicodeDecodeError``, when the
  file is opened or only when a variable is read; the variables asked for are therefore read
  into memory here, inside the check, and the file is closed again;
* the layout: a variable of speclight's schema (:data:`speclight.schema.VARIABLES`) on other
  dimensions than the schema's (an extra dimension, a renamed ``time``), or holding text
  where the schema gives units; no ``time`` dimension, or no ``time`` values. Times must be
  CF times (an integer or float variable with ``units = "seconds since 2020-01-01T00:00:00"``
  or the like, as speclight writes them): plain numbers without such units have no epoch to
  count from and are refused, never read as nanoseconds since 1970. Missing times (NaT) are
  refused.

:func:`values` reads one variable as floats on the dimensions a reader expects.
"""

from __future__ import annotations

from collections.abc import Collection
from pathlib import Path

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.input_files import check_user_file

#: The first bytes of an HDF5 file (NetCDF-4 is HDF5) and of a NetCDF-3 classic file.
HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
NETCDF3_SIGNATURE = b"CDF"
#: Dimensions whose size is fixed: the components of vectors and quaternions.
FIXED_SIZES = {"xyz": 3, "wxyz": 4}
#: What h5py's messages about an unreadable file mean, for a one-line error.
HDF5_PROBLEMS = {
    "file signature not found": "it is not a NetCDF4 (HDF5) file",
    "truncated file": "it is cut short (truncated)",
}
FIXED_SIZES_WHY = {"xyz": ("x", "y", "z"), "wxyz": ("w", "x", "y", "z")}


def read_user_dataset(
    path: str | Path,
    field: str | None,
    *,
    what: str = "NetCDF dataset",
    variables: Collection[str] | None = None,
    require_time: bool = True,
) -> xr.Dataset:
    """A NetCDF-4 dataset read into memory, checked as the module docstring says.

    Parameters
    ----------
    path
        The file.
    field
        The command-line argument that names it (``MEASURED``), for messages, or None.
    what
        What the file is, for messages.
    variables
        The variables to read (those the file lacks are left out; the caller checks what it
        needs); None for all of them. Coordinates and attributes are always read.
    require_time
        Refuse a dataset without a ``time`` dimension (else the caller says what it lacks).

    Raises
    ------
    InputError
        See the module docstring.
    """
    path = Path(path).expanduser()
    src = str(path)
    check_user_file(path, field, what=what, max_bytes=None)
    with open(path, "rb") as f:
        head = f.read(len(HDF5_SIGNATURE))
    if head.startswith(NETCDF3_SIGNATURE):
        raise _error(
            "cannot read it as a NetCDF dataset: it is NetCDF-3 (classic); speclight reads "
            "NetCDF-4 (HDF5) datasets: convert it, e.g. with nccopy -k nc4 IN OUT",
            src,
            field,
        )
    if head != HDF5_SIGNATURE:
        raise _unreadable(HDF5_PROBLEMS["file signature not found"], src, field)
    try:
        with xr.open_dataset(path, engine="h5netcdf") as opened:
            chosen = opened if variables is None else opened[[v for v in variables if v in opened]]
            ds = chosen.assign_coords(opened.coords).load()
    # HDF5 reports damaged bytes as KeyError, RuntimeError, OSError, UnicodeDecodeError...;
    # only the file's own opening and reading run here, not speclight's code
    except Exception as exc:
        said = " ".join(str(exc).split())  # h5py's can span lines
        why = next((w for key, w in HDF5_PROBLEMS.items() if key in said), None)
        why = why or f"the file is damaged ({type(exc).__name__}: {said})"
        raise _unreadable(why, src, field) from None
    _check_layout(ds, src, field, require_time)
    return ds


def values(
    ds: xr.Dataset, name: str, dims: tuple[str, ...], src: str, field: str | None
) -> NDArray[np.float64]:
    """``ds[name]`` as floats on ``dims`` (in that order), checked.

    Raises
    ------
    InputError
        The variable is on other dimensions or does not hold numbers.
    """
    da = ds[name]
    if set(da.dims) != set(dims):
        raise _error(_dims_message(name, da.dims, dims), src, field)
    if da.dtype.kind not in "biuf":
        raise _error(_not_numbers(name, da.dtype), src, field)
    return np.asarray(da.transpose(*dims).values, dtype=np.float64)


def _check_layout(ds: xr.Dataset, src: str, field: str | None, require_time: bool) -> None:
    from speclight.schema import VARIABLES

    for name, da in ds.data_vars.items():
        info = VARIABLES.get(str(name))
        if info is None:
            continue
        if set(da.dims) != set(info.dims):
            raise _error(_dims_message(str(name), da.dims, info.dims), src, field)
        if info.units and da.dtype.kind not in "biuf":
            raise _error(_not_numbers(str(name), da.dtype), src, field)
    for dim, size in FIXED_SIZES.items():
        if dim in ds.dims and ds.sizes[dim] != size:
            raise _error(
                f"the dimension '{dim}' has {ds.sizes[dim]} entries; a speclight dataset has "
                f"{size} ({', '.join(FIXED_SIZES_WHY[dim])})",
                src,
                field,
            )
    if "time" not in ds.dims and not require_time:
        return
    if "time" not in ds.dims:
        found = ", ".join(str(d) for d in ds.dims) or "none"
        raise _error(
            f"no 'time' dimension (its dimensions: {found}); a speclight dataset has its "
            "epochs on 'time'",
            src,
            field,
        )
    if "time" not in ds.coords:
        raise _error(
            "the 'time' dimension has no values (no 'time' variable); a speclight dataset "
            "stores its epochs as CF times",
            src,
            field,
        )
    t = ds["time"]
    if t.dtype.kind != "M":
        units = t.attrs.get("units") or t.encoding.get("units")
        how = f"units '{units}'" if units else "no units"
        raise _error(
            f"'time' holds {t.dtype} values with {how}, not CF times: give the epochs as "
            "numbers with units such as 'seconds since 2020-01-01T00:00:00' (UTC), as "
            "speclight writes them (plain numbers have no epoch to count from)",
            src,
            field,
        )
    nat = np.flatnonzero(np.isnat(t.values))
    if nat.size:
        raise _error(
            f"'time' is missing (NaT) at index {int(nat[0])} ({nat.size} of {t.size}); "
            "every epoch needs a time",
            src,
            field,
        )


def _dims_message(name: str, found: tuple[object, ...], expected: tuple[str, ...]) -> str:
    return (
        f"{name} is on the dimensions ({', '.join(str(d) for d in found)}); a speclight "
        f"dataset has it on ({', '.join(expected)})"
    )


def _not_numbers(name: str, dtype: np.dtype) -> str:
    return f"{name} holds {dtype} values, not numbers; a speclight dataset stores numbers"


def _unreadable(why: str, src: str, field: str | None) -> InputError:
    return _error(
        f"cannot read it as a NetCDF dataset: {why}; give a file written by `speclight simulate`",
        src,
        field,
    )


def _error(message: str, src: str, field: str | None) -> InputError:
    return InputError(message, source=src, field=field)
