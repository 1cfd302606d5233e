"""Start-up (issue 26 item 3): a simulation's steps do not import what they do not use.

Each check runs in a fresh interpreter (modules loaded by other tests would hide an import).
The start-up time itself is measured by bench/bench_startup.py, not here.
"""

import subprocess
import sys
import textwrap


def _fresh(code: str) -> str:
    run = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, check=False
    )
    assert run.returncode == 0, run.stderr
    return run.stdout


def test_writing_a_dataset_does_not_import_distributed() -> None:
    out = _fresh(
        """
        import sys
        import numpy as np
        import xarray as xr
        from speclight.io.netcdf import dataset_bytes
        ds = xr.Dataset({"x": (("t", "w"), np.arange(6.0).reshape(2, 3))})
        data = dataset_bytes(ds)
        back = xr.open_dataset(bytes(data), engine="h5netcdf")
        assert np.array_equal(back["x"].values, ds["x"].values)
        print("distributed" in sys.modules, "dask.distributed" in sys.modules)
        import distributed  # importable again afterwards: nothing was left blocked
        print(type(distributed).__name__)
        """
    )
    assert out.split() == ["False", "False", "module"]


def test_writing_with_distributed_loaded_uses_it() -> None:
    # Where a Client may exist (distributed imported), xarray's own check runs unchanged.
    out = _fresh(
        """
        import sys
        import distributed
        import numpy as np
        import xarray as xr
        from speclight.io.netcdf import dataset_bytes
        dataset_bytes(xr.Dataset({"x": ("t", np.arange(3.0))}))
        print(sys.modules["dask.distributed"] is not None)
        """
    )
    assert out.split() == ["True"]


def test_vega_band_and_plot_claims_do_not_import_astropy_or_matplotlib() -> None:
    out = _fresh(
        """
        import sys
        import numpy as np
        from speclight.instrument.bands import band_response
        from speclight.plot.figure_output import claim_outputs
        r = band_response(["bessell-V"], np.arange(400.0, 800.0, 5.0))
        assert r.shape == (1, 80) and r.max() > 0.9
        print(*(m in sys.modules for m in ("speclite.filters", "astropy", "matplotlib")))
        """
    )
    assert out.split() == ["False", "False", "False"]


def test_help_imports_no_engine_or_data_library() -> None:
    out = _fresh(
        """
        import sys
        from typer.testing import CliRunner
        from speclight.cli import app
        assert CliRunner().invoke(app, ["--help"]).exit_code == 0
        heavy = ("numpy", "xarray", "dask", "pandas", "scipy", "pvlib", "astropy", "skyfield",
                 "mitsuba", "drjit", "matplotlib", "speclite", "h5py")
        print([m for m in heavy if m in sys.modules])
        """
    )
    assert out.split() == ["[]"]


def test_a_simulation_without_dask_arrays_does_not_import_dask_array() -> None:
    # xarray would import dask.array (0.15-0.35 s) when it builds the first variable
    out = _fresh(
        """
        import sys
        import speclight
        overrides = {"time.stop": "2020-02-29T21:16:10Z", "time.step_s": 60.0,
                     "render.resolution_px": 16, "render.samples_per_pixel": 1}
        scenario = speclight.with_overrides(speclight.load("calsphere"), overrides)
        result = speclight.simulate(scenario)
        print(result.dataset.sizes["time"], "dask.array" in sys.modules)
        """
    )
    assert out.split() == ["4", "False"]
