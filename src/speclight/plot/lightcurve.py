"""Light curves per band: photo-electron rate and AB magnitude against time."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from speclight.plot.style import band_styles, shade_unobservable


def _legend(ax: Any, extra: list[Any]) -> None:
    handles, labels = ax.get_legend_handles_labels()
    handles += extra
    labels += [h.get_label() for h in extra]
    ax.legend(
        handles,
        labels,
        loc="upper left",
        bbox_to_anchor=(1.01, 1.0),
        fontsize="small",
        title="band",
        title_fontsize="small",
        frameon=False,
    )


def count_rate_panel(ds: xr.Dataset, ax: Any) -> None:
    """Noiseless count rate per band (lines) and the simulated measurement (dots)."""
    from matplotlib.lines import Line2D

    t = ds["time"].values
    styles = band_styles(ds)
    rate = ds["count_rate"].transpose("time", "band").values
    measured = (
        ds["count_rate_measured"].transpose("time", "band").values
        if "count_rate_measured" in ds
        else None
    )
    shade = shade_unobservable(ax, ds)
    for b, name in enumerate(ds["band"].values):
        if measured is not None:
            ax.plot(t, measured[:, b], ".", ms=2.0, alpha=0.45, color=styles[b]["color"])
        ax.plot(t, rate[:, b], lw=1.4, label=str(name), **styles[b])
    positive = rate[np.isfinite(rate) & (rate > 0)]
    if positive.size:
        ax.set_yscale("log")
        ax.set_ylim(bottom=max(positive.min(), positive.max() * 1e-6) / 2)
    extra = list(shade)
    if measured is not None:
        extra.append(Line2D([], [], ls="", marker=".", color="0.3", label="measured (with noise)"))
    _legend(ax, extra)
    ax.set_ylabel("photo-electron rate [s$^{-1}$]")
    ax.grid(alpha=0.3, which="both")
    ax.set_title("light curve per band", loc="left", fontsize="medium")


def magnitude_panel(ds: xr.Dataset, ax: Any) -> None:
    """AB magnitude per band (bright up)."""
    t = ds["time"].values
    styles = band_styles(ds)
    mag = ds["ab_magnitude"].transpose("time", "band").values
    shade_unobservable(ax, ds)
    for b in range(ds.sizes["band"]):
        ax.plot(t, mag[:, b], lw=1.4, **styles[b])
    if np.isfinite(mag).any():
        ax.invert_yaxis()
    ax.set_ylabel("AB magnitude [mag]")
    ax.grid(alpha=0.3)
