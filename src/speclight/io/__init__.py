"""Input/output: the NetCDF dataset writer."""

from speclight.io.netcdf import write_dataset

__all__ = ["write_dataset"]
