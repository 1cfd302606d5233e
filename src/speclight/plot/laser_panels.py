"""Laser panels of the overview (when the dataset has lasers): return rate and range offset.

The return rate is the detected laser photo-electrons per second of each band (all lasers);
the range offset the mean one-way return range minus the range to the centre of mass. Both
use the bands' colours; epochs without returns are gaps.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from speclight import schema
from speclight.plot.style import band_styles, shade_unobservable

#: (variable, panel height) of the laser panels, in overview order.
LASER_PANELS = (("return_rate", 1.8), ("range_offset", 1.6))


def laser_rows(ds: xr.Dataset) -> list[tuple[str, float]]:
    """The laser panels this dataset can fill."""
    return [(name, h) for name, h in LASER_PANELS if name in ds]


def _by_band(ds: xr.Dataset, name: str) -> tuple[list[str], np.ndarray]:
    var = ds[name]
    if "band" not in var.dims:
        var = var.expand_dims(band=["all"])
    values = np.asarray(var.transpose("time", "band").values, dtype=np.float64)
    return [str(b) for b in var["band"].values], values


def laser_panel(ds: xr.Dataset, name: str, ax: Any) -> None:
    """Draw ``return_rate`` (log scale) or ``range_offset`` [mm] per band against time."""
    t = ds["time"].values
    names, values = _by_band(ds, name)
    styles = band_styles(ds) if "band" in ds[name].dims else [{"color": "k"}]
    shade_unobservable(ax, ds)
    unit = str(ds[name].attrs.get("units", schema.units(name)))
    if name == "range_offset" and unit == "m":
        values, unit = values * 1e3, "mm"
    for b, _ in enumerate(names):
        ax.plot(t, values[:, b], lw=1.2, **styles[b % len(styles)])
    if name == "return_rate":
        positive = values[np.isfinite(values) & (values > 0)]
        if positive.size:
            ax.set_yscale("log")
            ax.set_ylim(bottom=max(positive.min(), positive.max() * 1e-6) / 2)
        ax.set_ylabel("laser returns [s$^{-1}$]")
        ax.set_title("laser return rate per band (all lasers)", loc="left", fontsize="medium")
    else:
        ax.set_ylabel(f"range offset [{unit}]")
        ax.set_title(
            "laser range offset per band (mean return - centre of mass, one-way)",
            loc="left",
            fontsize="medium",
        )
    ax.grid(alpha=0.3, which="both")
