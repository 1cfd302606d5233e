"""``speclight unmix`` end to end: run ``python bench/bench_unmix_cli.py`` and read the printout.

A synthetic speclight NetCDF of 10,000 epochs x 10 Gaussian bands (reflectance factors of
random mixtures of 4 tabulated endmember spectra, 1 % noise) and the 4 spectra as CSV
files are written to a temporary folder; then the command ``unmix MEASURED -e E1..E4 -o
ABUND.nc`` is timed (best of three) for every method and for ``--extract atgp --n 4``:

* in-process (typer's CliRunner, imports already done): the command's own work (reading the
  NetCDF and CSVs, band signatures, unmixing, building and writing ABUND.nc);
* as a new process (``python -m speclight.cli``), what a user waits for, interpreter start
  and imports included; the time of the imports alone is printed last.

The issue's target: under 1 s for 10,000 epochs x 10 bands x 4 endmembers.
"""

from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import xarray as xr
from typer.testing import CliRunner

from speclight.cli import app

TARGET_S = 1.0
WL = np.arange(300.0, 1240.0 + 2.5, 5.0)


def best_of(fn: Callable[[], object], repeat: int = 3) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def write_inputs(folder: Path, epochs: int, bands: int, k: int) -> tuple[Path, list[Path]]:
    rng = np.random.default_rng(0)
    centres = np.linspace(420.0, 1070.0, bands)
    response = np.exp(-0.5 * ((WL[None, :] - centres[:, None]) / 26.0) ** 2)
    files, spectra = [], []
    nodes = np.linspace(300.0, 1240.0, 8)
    for i in range(k):
        values = rng.uniform(0.05, 0.9, nodes.size)
        path = folder / f"material{i + 1}.csv"
        rows = [f"{x:g},{v:.4f}" for x, v in zip(nodes, values, strict=True)]
        path.write_text("wavelength_nm,reflectance\n" + "\n".join(rows) + "\n")
        files.append(path)
        spectra.append(np.interp(WL, nodes, np.round(values, 4)))
    # a Sun-like source and a transmission that changes with the epoch: the signatures are
    # weighted by each epoch's source at the aperture (SPEC section 5, eq. 5)
    solar = 1.9 * np.exp(-(((WL - 480.0) / 380.0) ** 2))
    transmission = (0.35 + 0.6 * (WL - WL[0]) / (WL[-1] - WL[0]))[None, :] ** np.linspace(
        1.0, 1.5, epochs
    )[:, None]
    w = response[None, :, :] * (solar * transmission)[:, None, :] * WL
    s = np.einsum("kl,nbl->nkb", np.array(spectra), w / w.sum(axis=2, keepdims=True))
    a = rng.dirichlet(np.ones(k), size=epochs) * 0.1
    x = np.einsum("nk,nkb->nb", a, s) + rng.normal(0.0, 0.001, size=(epochs, bands))
    time_utc = np.datetime64("2020-01-01T00:00:00", "ns") + np.arange(epochs) * np.timedelta64(
        1, "s"
    )
    ds = xr.Dataset(
        coords={"time": time_utc, "wavelength": WL, "band": [f"G-{c:.0f}/26" for c in centres]}
    )
    ds["band_response"] = (("band", "wavelength"), response)
    ds["solar_irradiance"] = (("time", "wavelength"), np.tile(solar, (epochs, 1)))
    ds["transmission"] = (("time", "wavelength"), transmission)
    ds["reflectance_factor"] = (("time", "band"), x)
    ds["count_rate"] = (("time", "band"), x * 1e4)
    measured = folder / "measured.nc"
    ds.to_netcdf(measured, engine="h5netcdf")
    return measured, files


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--epochs", type=int, default=10_000)
    parser.add_argument("--bands", type=int, default=10)
    parser.add_argument("--endmembers", type=int, default=4)
    args = parser.parse_args()
    print(
        f"python {platform.python_version()}, numpy {np.__version__}, {os.cpu_count()} cores; "
        f"{args.epochs} epochs x {args.bands} bands x {args.endmembers} endmembers"
    )
    runner = CliRunner()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        measured, files = write_inputs(folder, args.epochs, args.bands, args.endmembers)
        out = folder / "abund.nc"
        endmembers = ["-e", *map(str, files)]
        cases = {f"--method {m}": [*endmembers, "--method", m] for m in ("nnls-norm", "fcls")}
        cases["--method ls"] = [*endmembers, "--method", "ls"]
        cases["--extract atgp --n 4"] = ["--extract", "atgp", "--n", str(args.endmembers)]
        for label, extra in cases.items():
            argv = ["unmix", str(measured), *extra, "-o", str(out), "--force"]

            def in_process(argv: list[str] = argv) -> None:
                result = runner.invoke(app, argv)
                assert result.exit_code == 0, result.output

            def new_process(argv: list[str] = argv) -> None:
                cmd = [sys.executable, "-m", "speclight.cli", *argv]
                subprocess.run(cmd, check=True, capture_output=True)

            t_in = best_of(in_process)
            t_proc = best_of(new_process)
            flag = "ok" if t_proc < TARGET_S else f"OVER the {TARGET_S:.0f} s target"
            print(f"{label:24s} in-process {t_in:6.3f} s   new process {t_proc:6.3f} s  {flag}")
        for label, code in (
            (
                "python + import xarray, h5netcdf (the floor of any NetCDF command)",
                "import xarray, h5netcdf",
            ),
            (
                "python + import of what unmix imports",
                "import speclight.cli, speclight.estimate.spectra.unmix_run, speclight.io.netcdf, "
                "h5netcdf",
            ),
        ):
            t_import = best_of(
                lambda code=code: subprocess.run([sys.executable, "-c", code], check=True)
            )
            print(f"new process {t_import:6.3f} s: {label}")


if __name__ == "__main__":
    main()
