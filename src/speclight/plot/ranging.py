"""Ranging (when present): range offset per band and the range histogram of one epoch."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from speclight import schema
from speclight.plot.style import (
    band_styles,
    epoch_summary,
    flags,
    format_time_axis,
    new_figure,
    shade_unobservable,
)

EXCLUDED_FOR_LASER = (
    schema.FLAG_ORBIT_FAILED
    | schema.FLAG_BELOW_MIN_ELEVATION
    | schema.FLAG_RENDER_FAILED
    | schema.FLAG_DAYLIGHT
)


def has_ranging(ds: xr.Dataset) -> bool:
    """Whether the dataset has ``range_offset`` or ``range_histogram``."""
    return "range_offset" in ds or "range_histogram" in ds


def _units(ds: xr.Dataset, name: str) -> str:
    """The file's units of a variable, else the schema's."""
    return str(ds[name].attrs.get("units", schema.units(name)))


def strongest_return_epoch(ds: xr.Dataset) -> int | None:
    """Epoch with the most detected returns (all bands and bins), or None without any.

    Laser returns need no sunlight: only orbit, elevation and render failures exclude an
    epoch.
    """
    if "range_histogram" not in ds:
        return None
    hist = ds["range_histogram"]
    total = np.nan_to_num(hist.sum(dim=[d for d in hist.dims if d != "time"]).values)
    ok = (flags(ds) & EXCLUDED_FOR_LASER) == 0
    total = np.where(ok, total, 0.0)
    return int(np.argmax(total)) if total.max(initial=0.0) > 0 else None


def ranging_figure(ds: xr.Dataset, epoch: int | None) -> Any:
    """Range offset per band against time, and each band's range histogram at ``epoch``.

    ``epoch`` None: the epoch with the strongest returns (:func:`strongest_return_epoch`).
    """
    if epoch is None:
        epoch = strongest_return_epoch(ds)
    panels = [p for p in ("range_offset", "range_histogram") if p in ds]
    if epoch is None:
        panels = [p for p in panels if p != "range_histogram"]
    fig = new_figure(height_in=1.0 + 3.0 * max(len(panels), 1))
    axes = np.atleast_1d(fig.subplots(max(len(panels), 1), 1, squeeze=False)[:, 0])
    styles = band_styles(ds)
    bands = [str(b) for b in ds["band"].values] if "band" in ds.coords else []
    for ax, panel in zip(axes, panels, strict=False):
        if panel == "range_offset":
            offset = ds["range_offset"]
            if "band" not in offset.dims:
                offset = offset.expand_dims(band=["all"])
            unit = _units(ds, "range_offset")
            scale, unit = (1e3, "mm") if unit == "m" else (1.0, unit)
            shade_unobservable(ax, ds)
            for b, name in enumerate(offset["band"].values):
                style = styles[b] if b < len(styles) else {}
                y = offset.isel(band=b).values * scale
                ax.plot(ds["time"].values, y, lw=1.2, label=str(name), **style)
            ax.set_ylabel(f"range offset [{unit}]")
            ax.set_title("centre-of-mass range offset per band", loc="left", fontsize="medium")
            format_time_axis(ax, ds)
        elif epoch is not None:
            hist = ds["range_histogram"].isel(time=epoch)
            bin_dim = next(d for d in hist.dims if d != "band")
            x = hist[bin_dim].values if bin_dim in hist.coords else np.arange(hist.sizes[bin_dim])
            if "band" not in hist.dims:
                hist = hist.expand_dims(band=["all"])
            for b, name in enumerate(hist["band"].values):
                style = styles[b] if b < len(styles) and str(name) in bands else {}
                ax.step(x, hist.isel(band=b).values, where="mid", lw=1.2, label=str(name), **style)
            values = np.nan_to_num(np.asarray(hist.values, dtype=np.float64))
            support = np.flatnonzero(values.max(axis=0) > 0)
            if support.size:  # zoom on the returns, a quarter of their span either side
                lo, hi = float(x[support[0]]), float(x[support[-1]])
                pad = max(0.25 * (hi - lo), 2 * float(np.abs(np.diff(x)).min(initial=1.0)))
                ax.set_xlim(lo - pad, hi + pad)
                ax.set_yscale("log")
                ax.set_ylim(values.max() * 1e-4, values.max() * 2)
            unit = ds[bin_dim].attrs.get("units", "") if bin_dim in ds.coords else ""
            ax.set_xlabel(
                f"{str(bin_dim).replace('_', ' ')}: one-way range minus range to the centre of mass"
                + (f" [{unit}]" if unit else "")
            )
            hunit = _units(ds, "range_histogram").replace("s-1", "s$^{-1}$")
            ax.set_ylabel(f"returns per bin [{hunit}]")
            ax.set_title(
                f"range histogram, {epoch_summary(ds, epoch)}", loc="left", fontsize="medium"
            )
        ax.grid(alpha=0.3)
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small", frameon=False)
    name = ds.attrs.get("scenario_name", "speclight dataset")
    fig.suptitle(f"{name}: ranging")
    return fig
