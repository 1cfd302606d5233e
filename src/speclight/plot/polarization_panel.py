"""The overview's polarisation panel: degree of linear polarisation per band, and its angle."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from speclight.plot.style import band_styles, shade_unobservable


def has_polarization(ds: xr.Dataset) -> bool:
    """True when the dataset has the band polarisation (``render.polarization``)."""
    return "dolp" in ds and "band" in ds["dolp"].dims


def dolp_panel(ds: xr.Dataset, ax: Any) -> None:
    """DoLP per band [%] (solid lines, left axis) and AoLP [deg] (dots, right axis)."""
    t = ds["time"].values
    styles = band_styles(ds)
    dolp = ds["dolp"].transpose("time", "band").values * 100.0
    aolp = ds["aolp"].transpose("time", "band").values
    shade_unobservable(ax, ds)
    right = ax.twinx()
    for b in range(ds.sizes["band"]):
        ax.plot(t, dolp[:, b], lw=1.2, zorder=2, **styles[b])
        right.plot(t, aolp[:, b], ".", ms=2.5, alpha=0.6, color=styles[b]["color"])
    top = np.nanmax(dolp) if np.isfinite(dolp).any() else 1.0
    ax.set_ylim(0.0, max(1.0, 1.1 * top))
    right.set_ylim(0.0, 180.0)
    right.set_yticks([0, 45, 90, 135, 180])
    right.set_ylabel("AoLP [deg] (dots)", fontsize="small")
    ax.set_ylabel("DoLP [%]")
    ax.grid(alpha=0.3)
    ax.set_title(
        "linear polarisation per band (AoLP from celestial north through east)",
        loc="left",
        fontsize="medium",
    )
