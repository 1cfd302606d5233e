"""Laser and ranging variables of the output dataset (names, units: :mod:`speclight.schema`)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from speclight import schema

F64 = NDArray[np.float64]


@dataclass
class RangingResult:
    """Laser illumination and ranging outputs (arrays; :meth:`add_to` writes the variables)."""

    laser_names: list[str]
    band_names: list[str]
    range_bin_edges_m: F64
    laser_range_m: F64  # (N, K)
    laser_elevation_deg: F64  # (N, K)
    laser_irradiance_W_m2: F64  # (N, K)
    laser_intensity_W_sr_nm: F64  # (N, L)
    return_per_pulse: F64  # (N, K, B)
    return_rate_per_s: F64  # (N, B)
    range_histogram_per_s: F64  # (N, B, bins)
    range_offset_m: F64  # (N, B)
    reflectance_factor_m2_sr: F64  # (N, B) from the returns and the lasers' irradiance
    notes: list[str] = field(default_factory=list)

    def add_to(self, ds: xr.Dataset) -> xr.Dataset:
        """The dataset with the laser and ranging variables (:mod:`speclight.schema`)."""
        edges = self.range_bin_edges_m
        ds = ds.assign_coords(
            laser=("laser", np.array(self.laser_names, dtype=str)),
            range_bin=("range_bin", 0.5 * (edges[1:] + edges[:-1])),
        )
        ds["laser"].attrs.update(schema.COORDINATES["laser"])
        ds["range_bin"].attrs.update(schema.COORDINATES["range_bin"])
        bounds = np.stack([edges[:-1], edges[1:]], 1)
        ds["range_bin_bounds"] = (schema.BOUNDS["range_bin_bounds"], bounds)
        ds["laser_range"] = schema.variable("laser_range", self.laser_range_m)
        ds["laser_elevation"] = schema.variable("laser_elevation", self.laser_elevation_deg)
        ds["laser_irradiance"] = schema.variable("laser_irradiance", self.laser_irradiance_W_m2)
        ds["laser_intensity"] = schema.variable("laser_intensity", self.laser_intensity_W_sr_nm)
        if self.band_names:
            ds["return_photons_per_pulse"] = schema.variable(
                "return_photons_per_pulse", self.return_per_pulse
            )
            ds["return_rate"] = schema.variable("return_rate", self.return_rate_per_s)
            ds["range_histogram"] = schema.variable("range_histogram", self.range_histogram_per_s)
            ds["range_offset"] = schema.variable("range_offset", self.range_offset_m)
            ds["laser_reflectance_factor"] = schema.variable(
                "laser_reflectance_factor", self.reflectance_factor_m2_sr
            )
        return ds
