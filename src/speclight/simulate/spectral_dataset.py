"""Spectral, band and image variables of the output dataset (SPEC section 4)."""

from __future__ import annotations

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from speclight.render.result import RenderImage
from speclight.simulate import variables as v
from speclight.simulate.radiometry import Radiometry
from speclight.simulate.reflection import Reflection

TW = ("time", "wavelength")
TB = ("time", "band")


def add_spectral(
    ds: xr.Dataset,
    wavelength_nm: NDArray[np.float64],
    reflection: Reflection,
    transmission: NDArray[np.float64],
    radiometry: Radiometry | None,
) -> xr.Dataset:
    """Add the wavelength and band variables to a geometry dataset."""
    ds = ds.assign_coords(wavelength=("wavelength", wavelength_nm))
    ds["wavelength"].attrs.update(
        {"units": "nm", "long_name": "wavelength (bin centre)", "standard_name": "wavelength"}
    )
    ds["solar_irradiance"] = (TW, reflection.solar_irradiance_W_m2_nm, v.attrs("solar_irradiance"))
    ds["transmission"] = (TW, transmission, v.attrs("transmission"))
    if reflection.intensity_W_sr_nm is not None:
        ds["intensity"] = (TW, reflection.intensity_W_sr_nm, v.attrs("intensity"))
        ds["intensity_std"] = (TW, reflection.intensity_std_W_sr_nm, v.attrs("intensity_std"))
    if radiometry is None:
        return ds
    ds = ds.assign_coords(band=("band", np.array(radiometry.band_names, dtype=str)))
    ds["band"].attrs["long_name"] = "photometric band"
    ds["spectral_flux"] = (TW, radiometry.spectral_flux_W_nm, v.attrs("spectral_flux"))
    ds["count_rate"] = (TB, radiometry.count_rate_per_s, v.attrs("count_rate"))
    ds["ab_magnitude"] = (TB, radiometry.ab_magnitude, v.attrs("ab_magnitude"))
    if radiometry.count_rate_measured_per_s is not None:
        ds["count_rate_measured"] = (
            TB,
            radiometry.count_rate_measured_per_s,
            v.attrs("count_rate_measured"),
        )
    ds["band_response"] = (
        ("band", "wavelength"),
        radiometry.band_response,
        v.attrs("band_response"),
    )
    ds["optics_transmission"] = ("wavelength", radiometry.optics, v.attrs("optics_transmission"))
    ds["detector_qe"] = (("band", "wavelength"), radiometry.qe, v.attrs("detector_qe"))
    return ds


def add_images(ds: xr.Dataset, images: dict[int, RenderImage], part_names: list[str]) -> xr.Dataset:
    """Add saved hyperspectral images and depth maps on an ``image_time`` dimension.

    ``image_part`` carries the part names as CF ``flag_values`` / ``flag_meanings``.
    """
    if not images:
        return ds
    epochs = sorted(images)
    dims = ("image_time", "y", "x")
    radiance = np.stack([images[e].radiance_W_m2_sr_nm for e in epochs]).astype(np.float32)
    ds = ds.assign_coords(image_time=("image_time", ds["time"].values[epochs]))
    ds["image_time"].attrs["long_name"] = "epochs whose images are saved"
    ds["image_radiance"] = ((*dims, "wavelength"), radiance, v.attrs("image_radiance"))
    ds["image_depth"] = (
        dims,
        np.stack([images[e].depth_m for e in epochs]).astype(np.float32),
        v.attrs("image_depth"),
    )
    ds["image_part"] = (
        dims,
        np.stack([images[e].part_index for e in epochs]).astype(np.int16),
        {
            **v.attrs("image_part"),
            "flag_values": np.arange(len(part_names), dtype=np.int16),
            "flag_meanings": " ".join(name.replace(" ", "_") for name in part_names),
        },
    )
    ds["image_pixel_size"] = (
        ("image_time",),
        np.array([images[e].pixel_size_m for e in epochs]),
        {"units": "m", "long_name": "pixel pitch at the target"},
    )
    for name in ("right", "up"):
        ds[f"image_{name}_body"] = (
            ("image_time", "xyz"),
            np.stack([getattr(images[e], f"{name}_body") for e in epochs]),
            {"units": "1", "long_name": f"body-frame direction of the image's {name} axis"},
        )
    return ds
