"""Small synthetic speclight datasets for the plot tests (built here, not by the pipeline).

Uniquely named (not ``conftest``) so that test files can import it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

N_TIME = 60
WAVELENGTH_NM = np.arange(400.0, 1001.0, 10.0)
BANDS = {"G-450/30": 450.0, "G-650/30": 650.0, "G-850/30": 850.0}
# Brightness profile: the global maximum (epoch 5) is below the minimum elevation, so the
# brightest *observable* epoch is the local maximum at epoch 37 by construction.
PEAK_UNOBSERVABLE = 5
PEAK_OBSERVABLE = 37
IMAGE_EPOCHS = (20, 40)


def _profile() -> np.ndarray:
    k = np.arange(N_TIME)
    return (
        1.0
        + 5.0 * np.exp(-(((k - PEAK_UNOBSERVABLE) / 2.0) ** 2))
        + 2.0 * np.exp(-(((k - PEAK_OBSERVABLE) / 3.0) ** 2))
    )


def geometry_dataset() -> xr.Dataset:
    """Geometry only: range, elevation, phase angle, sunlit and flags on a time axis."""
    time = np.datetime64("2021-03-04T05:06:00", "ns") + np.arange(N_TIME) * np.timedelta64(1, "s")
    k = np.arange(N_TIME)
    flags = np.zeros(N_TIME, dtype=np.int32)
    flags[:10] |= 2  # below the minimum elevation
    flags[50:] |= 4  # in the Earth's shadow
    flags[47:50] |= 8  # penumbra
    sunlit = np.where(k >= 50, 0.0, np.where(k >= 47, 0.5, 1.0))
    ds = xr.Dataset(
        {
            "range": ("time", 1.5e6 + 2e4 * (k - 30) ** 2 / 30, {"units": "m"}),
            "azimuth": ("time", np.linspace(10.0, 170.0, N_TIME), {"units": "degree"}),
            "elevation": ("time", 5.0 + 40.0 * np.sin(np.pi * k / N_TIME), {"units": "degree"}),
            "phase_angle": ("time", np.linspace(30.0, 120.0, N_TIME), {"units": "degree"}),
            "sunlit": ("time", sunlit, {"units": "1"}),
            "flags": ("time", flags, {"units": "1"}),
        },
        coords={"time": time},
        attrs={"scenario_name": "synthetic-pass", "min_elevation_deg": 10.0},
    )
    return ds


def full_dataset() -> xr.Dataset:
    """Geometry plus the whole radiometric chain on 61 wavelengths and three bands."""
    ds = geometry_dataset()
    w = WAVELENGTH_NM
    sunlit = ds["sunlit"].values
    solar = np.broadcast_to(1.8 * np.exp(-(((w - 550.0) / 400.0) ** 2)), (N_TIME, w.size))
    intensity = 0.2 * _profile()[:, None] * sunlit[:, None] * solar
    intensity[:10] = np.nan  # not observable: NaN (SPEC section 4)
    transmission = np.broadcast_to(0.9 - 0.3 * np.exp(-(((w - 760.0) / 10.0) ** 2)), solar.shape)
    flux = intensity * transmission * 0.145 / ds["range"].values[:, None] ** 2
    response = np.exp(-0.5 * ((w[None, :] - np.array(list(BANDS.values()))[:, None]) / 30.0) ** 2)
    rate = flux @ (response * w * 1e-9 / 1.98644586e-25).T * 10.0
    with np.errstate(divide="ignore", invalid="ignore"):
        mag = -2.5 * np.log10(rate / 1e10)
    rng = np.random.default_rng(0)
    measured = np.where(np.isfinite(rate), rng.poisson(np.nan_to_num(rate)), np.nan)
    tw, tb = ("time", "wavelength"), ("time", "band")
    ds = ds.assign_coords(wavelength=("wavelength", w, {"units": "nm"}), band=list(BANDS))
    ds["solar_irradiance"] = (tw, solar.copy(), {"units": "W m-2 nm-1"})
    ds["intensity"] = (tw, intensity, {"units": "W sr-1 nm-1"})
    ds["intensity_std"] = (tw, 0.02 * np.nan_to_num(intensity), {"units": "W sr-1 nm-1"})
    ds["transmission"] = (tw, transmission.copy(), {"units": "1"})
    ds["spectral_flux"] = (tw, flux, {"units": "W nm-1"})
    ds["count_rate"] = (tb, rate, {"units": "s-1"})
    ds["count_rate_measured"] = (tb, measured.astype(float), {"units": "s-1"})
    ds["ab_magnitude"] = (tb, mag, {"units": "mag"})
    ds["band_response"] = (("band", "wavelength"), response, {"units": "1"})
    ds["optics_transmission"] = ("wavelength", np.full(w.size, 0.8), {"units": "1"})
    ds["detector_qe"] = (("band", "wavelength"), np.full(response.shape, 0.6), {"units": "1"})
    return ds


def image_dataset(size_px: int = 40) -> xr.Dataset:
    """The full dataset plus two saved images of a sphere-like disc and its depth map."""
    ds = full_dataset()
    c = (np.arange(size_px) + 0.5) / size_px * 2.0 - 1.0
    y, x = np.meshgrid(-c, c, indexing="ij")
    r2 = x**2 + y**2
    on = r2 < 0.8
    depth = np.where(on, -np.sqrt(np.clip(0.8 - r2, 0.0, None)), np.nan)
    shading = np.where(on, np.clip(0.2 + x + 0.5 * y, 0.0, None), 0.0)
    spectrum = np.exp(-(((WAVELENGTH_NM - 600.0) / 200.0) ** 2))
    radiance = shading[None, :, :, None] * spectrum * np.array([1.0, 0.5])[:, None, None, None]
    ds = ds.assign_coords(image_time=("image_time", ds["time"].values[list(IMAGE_EPOCHS)]))
    dims = ("image_time", "y", "x")
    ds["image_radiance"] = ((*dims, "wavelength"), radiance.astype(np.float32))
    ds["image_depth"] = (dims, np.stack([depth, depth]).astype(np.float32), {"units": "m"})
    ds["image_part"] = (dims, np.stack([np.where(on, 0, -1)] * 2).astype(np.int16))
    ds["image_pixel_size"] = ("image_time", np.array([0.05, 0.05]), {"units": "m"})
    return ds


def write(ds: xr.Dataset, path: Path) -> Path:
    ds.to_netcdf(path, engine="h5netcdf")
    return path
