"""Input/output: the NetCDF dataset writer and the claim on an output file.

``deferred_dask`` keeps xarray from importing ``dask.array`` before a dask array can exist
(the simulation's start-up).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from speclight.io.netcdf import write_dataset

__all__ = ["write_dataset"]


def __getattr__(name: str) -> Any:
    # imported on first use: the command line claims its output before xarray is loaded
    if name == "write_dataset":
        from speclight.io.netcdf import write_dataset

        return write_dataset
    raise AttributeError(f"module 'speclight.io' has no attribute {name!r}")
