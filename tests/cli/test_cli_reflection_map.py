"""``speclight reflection-map``: RMAP.nc per SPEC, per-pixel unmixing, figure, bad input.

The reference for the per-pixel contributions is the synthetic dataset of
``synthetic_mixture.py`` (reflectance factors ``a @ S`` from known contributions and band
signatures computed there from closed forms, not by speclight), with every epoch given a
body-frame phase vector at the centre of one of a few HEALPix pixels (astropy-healpix), each
pixel's epochs sharing one mixture: the map must give those mixtures back, pixel by pixel.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from astropy_healpix import healpix_to_xyz
from synthetic_mixture import mixture_dataset, write_spectra
from typer.testing import CliRunner

from speclight.cli import app

runner = CliRunner()
NAMES = ["gold", "cell", "paint"]
NSIDE = 8
PIXELS = [0, 37, 300, 767]
#: Noise-free unmixing is exact up to the solver's rounding (condition number of S ~ 10).
ROUNDING = 1e-9


def _mixtures() -> np.ndarray:
    return np.array([[0.6, 0.3, 0.1], [0.0, 1.0, 0.0], [0.2, 0.2, 0.6], [0.5, 0.0, 0.5]])


def _measured(tmp_path: Path, with_direction: bool = True) -> Path:
    """Five epochs per pixel of PIXELS (each pixel one mixture), then one unlit epoch."""
    a = np.repeat(_mixtures(), 5, axis=0)
    a = np.vstack([a, np.full((1, 3), np.nan)])
    ds = mixture_dataset(a, NAMES)
    pix = np.append(np.repeat(PIXELS, 5), PIXELS[0])
    x, y, z = healpix_to_xyz(pix, NSIDE, order="ring")
    if with_direction:
        ds["phase_vector_body"] = (("time", "xyz"), np.stack([x, y, z], axis=1), {"units": "1"})
    path = tmp_path / ("m.nc" if with_direction else "bare.nc")
    ds.to_netcdf(path, engine="h5netcdf")
    return path


def _run(*args: str):
    return runner.invoke(app, ["reflection-map", *args])


def test_rmap_per_spec_with_per_pixel_contributions_and_figure(tmp_path: Path) -> None:
    spectra = write_spectra(tmp_path)
    out, fig = tmp_path / "rmap.nc", tmp_path / "rmap.png"
    files = [str(spectra[n]) for n in NAMES]
    args = [str(_measured(tmp_path)), "-e", *files, "--nside", str(NSIDE), "-o", str(out)]
    result = _run(*args, "--plot", str(fig))
    assert result.exit_code == 0, result.output
    assert "20 epochs in 4 of 768 pixels" in result.output
    assert fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    ds = xr.open_dataset(out)
    assert ds.attrs["healpix_nside"] == NSIDE and ds.attrs["healpix_order"] == "ring"
    assert ds.attrs["frame"] == "body"
    assert ds["reflectance_factor"].dims == ("band", "pixel") and ds.sizes["pixel"] == 768
    for name in [*ds.data_vars, "lon", "lat"]:
        assert ds[name].attrs.get("units") is not None, name
        assert ds[name].attrs.get("long_name"), name
    n = ds["n_samples"].values
    np.testing.assert_array_equal(np.flatnonzero(n), PIXELS)
    assert np.all(n[PIXELS] == 5)
    # nnls-norm: the contributions as fractions of their sum (all mixtures sum to one)
    got = ds["abundance"].transpose("pixel", "endmember").values
    np.testing.assert_allclose(got[PIXELS], _mixtures(), atol=ROUNDING)
    others = np.setdiff1d(np.arange(768), PIXELS)
    assert np.all(np.isnan(got[others])) and np.all(np.isnan(ds["reflectance_factor"][:, others]))
    # the std of five identical mixtures is zero
    np.testing.assert_allclose(ds["reflectance_factor_std"].values[:, PIXELS], 0.0, atol=1e-15)


@pytest.mark.parametrize(
    "case", ["nside", "csv", "no-direction", "source", "exists", "band", "nan-direction", "bin"]
)
def test_bad_input_is_one_line_and_exit_2(tmp_path: Path, case: str) -> None:
    measured = _measured(tmp_path)
    out = tmp_path / "rmap.nc"
    args = [str(measured), "-o", str(out)]
    needle = {
        "nside": "--nside = 12 must be a power of 2",
        "csv": "give --scenario",
        "no-direction": "no phase_vector_body",
        "source": "--source = 'moon'",
        "exists": "exists",
        "band": "unknown band 'X'",
        "nan-direction": "the map would be empty: measured 2020-",
        "bin": "--bin-s = 1e+09 s is not shorter than the",
    }[case]
    if case == "nside":
        args += ["--nside", "12"]
    elif case == "csv":
        csv = tmp_path / "rates.csv"
        csv.write_text("time,G-430/25\n2020-02-29T21:16:00Z,100.0\n")
        args[0] = str(csv)
    elif case == "no-direction":
        args[0] = str(_measured(tmp_path, with_direction=False))
    elif case == "source":
        args += ["--source", "moon"]
    elif case == "exists":
        out.write_text("keep me")
    elif case == "band":
        args += ["--plot", str(tmp_path / "f.png"), "--band", "X"]
    elif case == "nan-direction":  # every phase vector NaN: no epoch has a direction
        ds = xr.load_dataset(measured, engine="h5netcdf")
        ds["phase_vector_body"][:] = np.nan
        ds.to_netcdf(tmp_path / "nan.nc", engine="h5netcdf")
        args[0] = str(tmp_path / "nan.nc")
    elif case == "bin":
        args += ["--bin-s", "1e9"]
    result = _run(*args)
    assert result.exit_code == 2, result.output
    assert needle in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    assert "Traceback" not in result.output
    if case == "exists":
        assert out.read_text() == "keep me"
    else:
        assert not out.exists()
