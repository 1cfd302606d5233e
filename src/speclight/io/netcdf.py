"""Write the output dataset as NetCDF4 (CF conventions), atomically.

The dataset is serialised in memory first (HDF5 then never touches the disk, so a full disk
is an ordinary ``OSError`` instead of a crash inside HDF5) and written by
:class:`~speclight.io.output.OutputClaim`, which moves the file into place only when
complete: a failed or interrupted run never leaves a half-written file, and an existing file
is replaced only when ``force`` is set. The memory needed is about twice the file's size.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import xarray as xr

from speclight.io.held_signals import hold_signals
from speclight.io.output import OutputClaim


def _encoding(ds: xr.Dataset) -> dict[str, dict[str, object]]:
    enc: dict[str, dict[str, object]] = {}
    for name, var in ds.data_vars.items():
        if var.dtype.kind == "f" and var.ndim >= 2:
            enc[str(name)] = {"zlib": True, "complevel": 4, "shuffle": True}
    # CF-1.10 section 2.5.1: coordinate variables must not have a _FillValue (they have no
    # missing values); xarray gives every float variable one unless told not to. Boundary
    # variables take their coordinate's rules (section 7.1).
    for name in [*ds.coords, *(n for n in ds.data_vars if str(n).endswith("_bounds"))]:
        if ds[name].dtype.kind in "fcM":
            enc.setdefault(str(name), {})["_FillValue"] = None
    if "time" in ds.coords:
        enc["time"].update(units="microseconds since 1970-01-01T00:00:00", dtype=np.int64)
    return enc


def dataset_bytes(ds: xr.Dataset) -> memoryview:
    """The NetCDF4 file of ``ds`` (h5netcdf), in memory.

    SIGINT, SIGTERM and SIGHUP are held back while HDF5 writes (it would drop the exception
    of an interrupt, see :mod:`speclight.io.held_signals`) and act when it is done.
    """
    with hold_signals(), _no_distributed_import():
        data = ds.to_netcdf(None, engine="h5netcdf", encoding=_encoding(ds))
    return memoryview(data)


@contextmanager
def _no_distributed_import() -> Iterator[None]:
    """Keep xarray's writer from importing ``dask.distributed`` where it cannot matter.

    ``to_netcdf`` asks whether the active Dask scheduler is a ``distributed.Client`` by
    importing ``distributed`` (through ``dask.base.get_scheduler`` and ``dask.distributed``;
    0.3-0.9 s, the largest part of a run's start-up). A Client exists only if
    ``distributed`` was imported already; if it was not, the answer is "no" and the import
    is skipped (``None`` in ``sys.modules`` makes it raise ImportError,
    which xarray takes as "no distributed scheduler"). Where ``distributed`` is loaded (a
    sweep, a Dask worker), nothing changes.
    """
    names = ("distributed", "dask.distributed")
    if any(name in sys.modules for name in names):
        yield
        return
    for name in names:
        sys.modules[name] = None  # type: ignore[assignment]
    try:
        yield
    finally:
        for name in names:
            if name in sys.modules and sys.modules[name] is None:
                del sys.modules[name]


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

    Raises
    ------
    InputError
        ``path`` exists (without ``force``), is a folder, is in a missing or unwritable
        folder, or is being written by another run.
    OutputWriteError
        The file system refused the write (full disk...); nothing was left behind.
    """
    with OutputClaim(path, force=force) as claim:
        return claim.write(dataset_bytes(ds))
