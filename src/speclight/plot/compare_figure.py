"""Figure of ``speclight compare``: residuals against time and phase angle, and where the
Sun and the observer were in the body frame, coloured by the residual.

Colour tells the bands apart, the marker the sites; residuals carry the observed
magnitude's standard deviation as error bars (none where the file gave none).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from speclight.plot.style import new_figure, set_time_ticks

#: Marker of each site, in the order the sites first appear (cycled beyond eight).
SITE_MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*")


def _lon_lat_deg(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Body-frame longitude (atan2(y, x)) and latitude (asin z) of unit vectors [deg]."""
    lon = np.degrees(np.arctan2(v[:, 1], v[:, 0]))
    lat = np.degrees(np.arcsin(np.clip(v[:, 2], -1.0, 1.0)))
    return lon, lat


def site_index(ds: xr.Dataset) -> tuple[np.ndarray, list[str]]:
    """Each observation's site number (first-seen order) and a label per site."""
    keys = list(
        zip(
            ds["site_latitude"].values.tolist(),
            ds["site_longitude"].values.tolist(),
            ds["site_altitude"].values.tolist(),
            strict=True,
        )
    )
    sites = list(dict.fromkeys(keys))
    labels = [
        f"site {k + 1}: {abs(lat):.4f}° {'N' if lat >= 0 else 'S'}, "
        f"{abs(lon):.4f}° {'E' if lon >= 0 else 'W'}, {alt:.0f} m"
        for k, (lat, lon, alt) in enumerate(sites)
    ]
    return np.array([sites.index(k) for k in keys], dtype=np.intp), labels


def _legend_handles(bands: list[str], colours: dict[str, Any], site_labels: list[str]) -> list:
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color=colours[b], marker="o", ls="", ms=5, label=b) for b in bands]
    if len(site_labels) > 1:
        for k, label in enumerate(site_labels):
            marker = SITE_MARKERS[k % len(SITE_MARKERS)]
            handles.append(Line2D([], [], color="0.3", marker=marker, ls="", ms=5, label=label))
    return handles


def compare_figure(ds: xr.Dataset) -> Any:
    """The figure (a matplotlib ``Figure``) of a CMP.nc dataset."""
    from matplotlib import colormaps

    fig = new_figure(7.5)
    (ax_t, ax_p), (ax_s, ax_o) = fig.subplots(2, 2)
    r = ds["residual"].values.astype(float)
    sigma = ds["magnitude_sigma"].values.astype(float)
    ok = np.isfinite(r)
    lim = float(np.nanmax(np.abs(r))) if ok.any() else 1.0
    bands = np.array([str(b) for b in ds["band"].values])
    names = list(dict.fromkeys(bands.tolist()))
    colours = {b: colormaps["tab10"](i % 10) for i, b in enumerate(names)}
    site, site_labels = site_index(ds)
    for k in range(len(site_labels)):
        marker = SITE_MARKERS[k % len(SITE_MARKERS)]
        for name in names:
            sel = ok & (bands == name) & (site == k)
            if not sel.any():
                continue
            style = {"fmt": marker, "ms": 4, "color": colours[name], "capsize": 2, "lw": 0.8}
            yerr = np.where(np.isfinite(sigma[sel]), sigma[sel], 0.0)
            ax_t.errorbar(ds["time"].values[sel], r[sel], yerr=yerr, **style)
            ax_p.errorbar(ds["phase_angle"].values[sel], r[sel], yerr=yerr, **style)
    for ax in (ax_t, ax_p):
        ax.axhline(0.0, color="0.5", lw=0.8)
        ax.set_ylabel("observed - simulated [mag]")
        ax.invert_yaxis()  # up: brighter than simulated
    set_time_ticks(ax_t)
    ax_t.set_xlabel("time [UTC]")
    ax_p.set_xlabel("phase angle [deg]")
    handles = _legend_handles(names, colours, site_labels)
    fig.legend(handles=handles, loc="outside lower center", ncols=min(len(handles), 4),
               fontsize="small", frameon=False)  # fmt: skip
    scatter = None
    for ax, name, title in (
        (ax_s, "sun_direction_body", "Sun direction, body frame"),
        (ax_o, "observer_direction_body", "observer direction, body frame"),
    ):
        lon, lat = _lon_lat_deg(ds[name].values)
        for k in range(len(site_labels)):
            sel = ok & (site == k)
            scatter = ax.scatter(lon[sel], lat[sel], c=r[sel], s=14, cmap="coolwarm",
                                 vmin=-lim, vmax=lim, marker=SITE_MARKERS[k % len(SITE_MARKERS)],
                                 edgecolors="0.3", linewidths=0.3)  # fmt: skip
        ax.set_xlim(-180, 180)
        ax.set_ylim(-90, 90)
        ax.set_xlabel("longitude atan2(y, x) [deg]")
        ax.set_ylabel("latitude asin(z) [deg]")
        ax.set_title(title, fontsize="medium")
    if scatter is not None:
        fig.colorbar(scatter, ax=[ax_s, ax_o], label="observed - simulated [mag]")
    a = ds.attrs
    fig.suptitle(
        f"{a['residual_n']} observations from {len(site_labels)} site"
        f"{'s' if len(site_labels) != 1 else ''}: mean {a['residual_mean_mag']:+.3f} mag, "
        f"RMS {a['residual_rms_mag']:.3f} mag (error bars: the observed magnitudes' sigma)",
        fontsize="medium",
    )
    return fig
