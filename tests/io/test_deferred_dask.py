"""xarray's dask record answers from sys.modules (speclight.io.deferred_dask, issue 26 item 3).

Each check runs in a fresh interpreter: modules loaded by other tests (dask.array through the
maps or the scale tests) would hide an import. The references are dask's own array class and
version, and xarray's own behaviour with dask arrays (chunks, values).
"""

import subprocess
import sys
import textwrap


def _fresh(code: str) -> list[str]:
    run = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, check=False
    )
    assert run.returncode == 0, run.stderr
    return run.stdout.split()


def test_building_and_writing_a_dataset_does_not_import_dask_array() -> None:
    out = _fresh(
        """
        import sys
        import numpy as np
        import xarray as xr
        from speclight.io.deferred_dask import defer_dask_array_import
        from speclight.io.netcdf import dataset_bytes
        print(defer_dask_array_import(), defer_dask_array_import())  # in place; twice is fine
        ds = xr.Dataset(
            {"x": (("time", "w"), np.arange(6.0).reshape(2, 3))},
            coords={"time": np.array(["2020-01-01", "2020-01-02"], dtype="datetime64[ns]")},
        )
        back = xr.open_dataset(bytes(dataset_bytes(ds)), engine="h5netcdf")
        assert np.array_equal(back["x"].values, ds["x"].values)
        print("dask.array" in sys.modules)
        """
    )
    # True with the installed xarray: if an xarray upgrade moves the cache this fails here
    # (the run would still be right, only slower) instead of going unnoticed
    assert out == ["True", "True", "False"]


def test_dask_arrays_stay_dask_arrays_once_dask_array_is_imported() -> None:
    out = _fresh(
        """
        import numpy as np
        import xarray as xr
        from xarray.namedarray.pycompat import array_type, mod_version
        from speclight.io.deferred_dask import defer_dask_array_import
        defer_dask_array_import()
        xr.DataArray(np.zeros(3))  # xarray asks about dask: no dask array type yet
        print(array_type("dask") == ())
        import dask
        import dask.array as da
        print(array_type("dask") == (da.Array,))
        print(str(mod_version("dask")) == dask.__version__)
        masked = da.from_array(np.ma.masked_array([1.0, 2.0, 3.0], mask=[0, 1, 0]), chunks=2)
        a = xr.DataArray(masked, dims="x")  # xarray's masked-dask branch needs the type
        print(a.chunks == ((2, 1),), isinstance(a.data, da.Array))
        print(np.array_equal(a.values, [1.0, np.nan, 3.0], equal_nan=True))
        """
    )
    assert out == ["True", "True", "True", "True", "True", "True"]


def test_an_earlier_dask_record_is_left_alone() -> None:
    out = _fresh(
        """
        import dask.array
        import numpy as np
        import xarray as xr
        from xarray.namedarray import pycompat
        from speclight.io.deferred_dask import defer_dask_array_import
        xr.DataArray(np.zeros(3))  # xarray's own record of dask, made with dask.array loaded
        record = pycompat._cached_duck_array_modules["dask"]
        print(defer_dask_array_import(), pycompat._cached_duck_array_modules["dask"] is record)
        """
    )
    assert out == ["False", "True"]
