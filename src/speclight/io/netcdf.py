"""Write the output dataset as NetCDF4 (CF conventions), atomically.

The file is written to a temporary name beside the target and moved into place only
when complete, so a failed run never leaves a half-written file; an existing file is
replaced only when ``force`` is set.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np
import xarray as xr

from speclight.errors import InputError


def check_writable(path: str | Path, force: bool = False) -> Path:
    """Fail early (before any work) if ``path`` exists and ``force`` is not set."""
    path = Path(path)
    if path.exists() and not force:
        raise InputError(
            f"{path} exists; choose another name or pass --force to overwrite it",
            field="--output",
        )
    if path.is_dir():
        raise InputError(f"{path} is a folder; give a file name such as out.nc", field="--output")
    if not path.parent.exists():
        raise InputError(f"folder {path.parent} does not exist", field="--output")
    return path


def _encoding(ds: xr.Dataset) -> dict[str, dict[str, object]]:
    enc: dict[str, dict[str, object]] = {}
    for name, var in ds.data_vars.items():
        if var.dtype.kind == "f" and var.ndim >= 2:
            enc[str(name)] = {"zlib": True, "complevel": 4, "shuffle": True}
    if "time" in ds.coords:
        enc["time"] = {"units": "microseconds since 1970-01-01T00:00:00", "dtype": np.int64}
    return enc


def write_dataset(ds: xr.Dataset, path: str | Path, force: bool = False) -> Path:
    """Write ``ds`` to ``path`` (NetCDF4 via h5netcdf), atomically.

    Parameters
    ----------
    ds
        The dataset to write.
    path
        Destination file.
    force
        Replace an existing file.

    Returns
    -------
    Path
        The written file.
    """
    path = check_writable(path, force)
    fd, tmp_name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        ds.to_netcdf(tmp_name, engine="h5netcdf", encoding=_encoding(ds))
        os.replace(tmp_name, path)
    except BaseException:
        Path(tmp_name).unlink(missing_ok=True)
        raise
    return path
