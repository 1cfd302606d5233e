"""Light curves per band: photo-electron rate and AB magnitude against time.

Up to :data:`MAX_LEGEND_BANDS` bands are named in a legend; with more, the bands are told
apart by colour alone (their mean wavelength) and a colour bar over wavelength replaces the
legend. The simulated measurements (with noise) are drawn as small translucent markers
*above* the noiseless model lines, so that the scatter stays visible where the two overlap.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from speclight.plot.style import (
    band_centres_nm,
    band_styles,
    shade_unobservable,
    wavelength_colour_map,
)

#: Most bands named in one legend; more get a colour bar over wavelength instead.
MAX_LEGEND_BANDS = 6


def _legend(ax: Any, extra: list[Any], with_bands: bool) -> None:
    handles, labels = ax.get_legend_handles_labels() if with_bands else ([], [])
    handles += extra
    labels += [h.get_label() for h in extra]
    if not handles:
        return
    ax.legend(
        handles,
        labels,
        loc="upper left",
        bbox_to_anchor=(1.01 if with_bands else 1.11, 1.0),  # right of the colour bar
        fontsize="small",
        title="band" if with_bands else None,
        title_fontsize="small",
        frameon=False,
    )


def many_bands(ds: xr.Dataset) -> bool:
    """More bands than a legend can name readably (:data:`MAX_LEGEND_BANDS`)."""
    return int(ds.sizes.get("band", 0)) > MAX_LEGEND_BANDS


def band_colour_bar(ds: xr.Dataset, fig: Any, ax: Any) -> Any:
    """Colour bar of the band colours over wavelength, ticks at the bands' mean wavelengths."""
    from matplotlib.cm import ScalarMappable

    cmap, norm = wavelength_colour_map()
    cax = ax.inset_axes((1.015, 0.0, 0.018, 1.0))
    bar = fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), cax=cax)
    bar.set_label("band mean wavelength [nm]", fontsize="small")
    centres = band_centres_nm(ds)
    centres = centres[np.isfinite(centres)]
    if centres.size:
        bar.ax.set_ylim(max(norm.vmin, centres.min() - 30), min(norm.vmax, centres.max() + 30))
        bar.ax.hlines(centres, 0, 1, colors="k", lw=0.6)
    return bar


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
        ax.plot(t, rate[:, b], lw=1.2, label=str(name), zorder=2, **styles[b])
        if measured is not None:  # on top of the lines, small and translucent
            ax.plot(t, measured[:, b], ".", ms=2.5, alpha=0.5, color=styles[b]["color"], zorder=3)
    positive = rate[np.isfinite(rate) & (rate > 0)]
    if positive.size:
        ax.set_yscale("log")
        ax.set_ylim(bottom=max(positive.min(), positive.max() * 1e-6) / 2)
    extra = list(shade)
    if measured is not None:
        extra.append(Line2D([], [], ls="", marker=".", color="0.3", label="measured (with noise)"))
        extra.append(Line2D([], [], color="0.3", lw=1.2, label="model (noiseless)"))
    _legend(ax, extra, with_bands=not many_bands(ds))
    if many_bands(ds):
        band_colour_bar(ds, ax.figure, ax)
    ax.set_ylabel("photo-electron rate [s$^{-1}$]")
    ax.grid(alpha=0.3, which="both")
    ax.set_title("light curve per band", loc="left", fontsize="medium")


#: ``--magnitude`` choices: the dataset variable and the panel's axis label.
MAGNITUDES = {
    "ab": ("ab_magnitude", "AB magnitude [mag]"),
    "exo": ("ab_magnitude_exo", "AB mag, above the atmosphere"),
    "standard": ("ab_magnitude_standard", "AB mag at 1000 km, above atm."),
    "vega": ("vega_v_magnitude", "Vega V magnitude [mag]"),
}


def magnitude_panel(ds: xr.Dataset, ax: Any, kind: str = "ab") -> None:
    """Magnitudes (bright up): per band, or Vega V (one curve); ``kind`` in
    :data:`MAGNITUDES`."""
    name, label = MAGNITUDES[kind]
    t = ds["time"].values
    shade_unobservable(ax, ds)
    if "band" in ds[name].dims:
        styles = band_styles(ds)
        mag = ds[name].transpose("time", "band").values
        for b in range(ds.sizes["band"]):
            ax.plot(t, mag[:, b], lw=1.4, **styles[b])
    else:
        mag = ds[name].values
        ax.plot(t, mag, lw=1.4, color="0.2", label="Vega V")
    if np.isfinite(mag).any():
        ax.invert_yaxis()
    ax.set_ylabel(label)
    ax.grid(alpha=0.3)
