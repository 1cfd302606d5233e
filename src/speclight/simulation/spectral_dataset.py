"""Spectral, band and image variables of the output dataset (docs/output.md)."""

from __future__ import annotations

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from speclight import schema
from speclight.render.result import RenderImage
from speclight.simulation.radiometry import Radiometry
from speclight.simulation.reflection import Reflection


def add_spectral(
    ds: xr.Dataset,
    wavelength_nm: NDArray[np.float64],
    reflection: Reflection,
    transmission: NDArray[np.float64],
    radiometry: Radiometry | None,
) -> xr.Dataset:
    """Add the wavelength and band variables to a geometry dataset."""
    ds = ds.assign_coords(wavelength=("wavelength", wavelength_nm))
    ds["wavelength"].attrs.update(schema.COORDINATES["wavelength"])
    ds["solar_irradiance"] = schema.variable(
        "solar_irradiance", reflection.solar_irradiance_W_m2_nm
    )
    ds["transmission"] = schema.variable("transmission", transmission)
    if reflection.intensity_W_sr_nm is not None:
        ds["intensity"] = schema.variable("intensity", reflection.intensity_W_sr_nm)
        ds["intensity_std"] = schema.variable("intensity_std", reflection.intensity_std_W_sr_nm)
        if reflection.earthshine_W_sr_nm is not None:
            ds["earthshine_intensity"] = schema.variable(
                "earthshine_intensity", reflection.earthshine_W_sr_nm
            )
        if reflection.outside_support_fraction is not None:
            ds["outside_support_fraction"] = schema.variable(
                "outside_support_fraction", reflection.outside_support_fraction
            )
    if radiometry is None:
        return ds
    ds = ds.assign_coords(band=("band", np.array(radiometry.band_names, dtype=str)))
    ds["band"].attrs.update(schema.COORDINATES["band"])
    ds["spectral_flux"] = schema.variable("spectral_flux", radiometry.spectral_flux_W_nm)
    ds["count_rate"] = schema.variable("count_rate", radiometry.count_rate_per_s)
    ds["ab_magnitude"] = schema.variable("ab_magnitude", radiometry.ab_magnitude)
    for name in (
        "ab_magnitude_exo",
        "ab_magnitude_standard",
        "vega_v_magnitude",
        "vega_v_magnitude_standard",
    ):
        values = getattr(radiometry, name)
        if values is not None:
            ds[name] = schema.variable(name, values)
    if radiometry.count_rate_measured_per_s is not None:
        ds["count_rate_measured"] = schema.variable(
            "count_rate_measured", radiometry.count_rate_measured_per_s
        )
    if radiometry.reflectance_factor_m2_sr is not None:
        ds["reflectance_factor"] = schema.variable(
            "reflectance_factor", radiometry.reflectance_factor_m2_sr
        )
    ds["band_response"] = schema.variable("band_response", radiometry.band_response)
    ds["optics_transmission"] = schema.variable("optics_transmission", radiometry.optics)
    ds["detector_qe"] = schema.variable("detector_qe", radiometry.qe)
    return ds


def add_images(ds: xr.Dataset, images: dict[int, RenderImage], part_names: list[str]) -> xr.Dataset:
    """Add saved hyperspectral images and depth maps on an ``image_time`` dimension.

    With per-pixel Stokes Q, U (single mode, ``render.polarization``) also
    ``image_radiance_q`` and ``image_radiance_u``.

    ``image_part`` carries the part names as CF ``flag_values`` / ``flag_meanings``.
    """
    if not images:
        return ds
    epochs = sorted(images)
    radiance = np.stack([images[e].radiance_W_m2_sr_nm for e in epochs]).astype(np.float32)
    ds = ds.assign_coords(image_time=("image_time", ds["time"].values[epochs]))
    ds["image_time"].attrs.update(schema.COORDINATES["image_time"])
    ds["image_radiance"] = schema.variable("image_radiance", radiance)
    _add_image_stokes(ds, [images[e] for e in epochs])
    return _add_image_geometry(ds, [images[e] for e in epochs], part_names)


def _add_image_stokes(ds: xr.Dataset, images: list[RenderImage]) -> None:
    """The kept images' per-pixel Stokes Q, U, where every image has them (single mode with
    ``render.polarization``)."""
    stokes = [image.stokes_qu_W_m2_sr_nm for image in images]
    if all(s is not None for s in stokes):
        qu = np.stack([s for s in stokes if s is not None]).astype(np.float32)
        ds["image_radiance_q"] = schema.variable("image_radiance_q", qu[..., 0])
        ds["image_radiance_u"] = schema.variable("image_radiance_u", qu[..., 1])


def _add_image_geometry(
    ds: xr.Dataset, kept: list[RenderImage], part_names: list[str]
) -> xr.Dataset:
    """The kept images' depth maps, part maps, pixel sizes and image axes."""
    depth = np.stack([image.depth_m for image in kept]).astype(np.float32)
    ds["image_depth"] = schema.variable("image_depth", depth)
    ds["image_part"] = schema.variable(
        "image_part",
        np.stack([image.part_index for image in kept]).astype(np.int16),
        flag_values=np.arange(len(part_names), dtype=np.int16),
        flag_meanings=" ".join(name.replace(" ", "_") for name in part_names),
    )
    pitch = np.array([image.pixel_size_m for image in kept])
    ds["image_pixel_size"] = schema.variable("image_pixel_size", pitch)
    for name in ("right", "up"):
        axis = np.stack([getattr(image, f"{name}_body") for image in kept])
        ds[f"image_{name}_body"] = schema.variable(f"image_{name}_body", axis)
    return ds
