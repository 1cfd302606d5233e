"""Figure of ``speclight spin-axis`` from its AXIS.nc (the reference paper's Figure 18).

Top left: the misfit surface ``error(ra, dec)`` (minimised over the phase), log colour scale, on
an RA/Dec plate carree, with the best cell, the mirror minimum, the refined axis and the
scenario's own axis (the truth of a simulated pass) marked. Top right: the best phase per
cell. Bottom: the observation tracks (the phase vector in the body frame, longitude and
latitude) of the scenario's attitude (the true track), the best cell and the refined axis.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from speclight.plot.style import new_figure

MARKS = (
    ("best", "o", "white", "best cell"),
    ("mirror", "s", "cyan", "mirror minimum"),
    ("refined", "+", "red", "refined"),
    ("scenario", "x", "magenta", "scenario axis"),
)


def _mark(ax: Any, ds: xr.Dataset) -> None:
    for key, marker, colour, label in MARKS:
        ra, dec = ds.attrs.get(f"{key}_ra_deg"), ds.attrs.get(f"{key}_dec_deg")
        if ra is None or not np.isfinite(ra):
            continue
        ax.plot(
            [ra], [dec], marker=marker, ms=9, mfc="none", mec=colour, mew=1.8, ls="", label=label
        )


def spin_axis_figure(ds: xr.Dataset) -> Any:
    """The misfit surface and the best phase of an AXIS.nc dataset."""
    from matplotlib.colors import LogNorm

    tracks = "track_lon" in ds
    fig = new_figure(8.0 if tracks else 4.2, 11.0)
    axes = fig.subplots(2, 2) if tracks else fig.subplots(1, 2)[None, :]
    ax_e, ax_p = axes[0]
    ra, dec = ds["ra"].values, ds["dec"].values
    e = ds["error"].transpose("dec", "ra").values
    finite = e[np.isfinite(e) & (e > 0)]
    norm = LogNorm(vmin=finite.min(), vmax=finite.max()) if finite.size else None
    mesh = ax_e.pcolormesh(ra, dec, e, shading="nearest", cmap="viridis", norm=norm)
    fig.colorbar(mesh, ax=ax_e, label="misfit (normalised light curves)")
    _mark(ax_e, ds)
    ax_e.legend(loc="lower left", fontsize=7, framealpha=0.6)
    ax_e.set_title("misfit over the spin axis (min over phase)")
    mesh_p = ax_p.pcolormesh(
        ra,
        dec,
        ds["best_phase"].transpose("dec", "ra").values,
        shading="nearest",
        cmap="twilight",
        vmin=0.0,
        vmax=360.0,
    )
    fig.colorbar(mesh_p, ax=ax_p, label="best phase at the start [deg]")
    _mark(ax_p, ds)
    ax_p.set_title("phase of the best fit")
    for ax in (ax_e, ax_p):
        ax.set_xlim(0, 360)
        ax.set_ylim(-90, 90)
        ax.set_xlabel("spin axis RA (GCRS) [deg]")
        ax.set_ylabel("spin axis Dec [deg]")
    if tracks:
        _tracks(axes[1, 0], ds)
        axes[1, 1].set_visible(False)
    return fig


def _tracks(ax: Any, ds: xr.Dataset) -> None:
    styles = {"scenario": ("k", "true track (scenario)"), "best": ("C0", "best cell")}
    styles["refined"] = ("C3", "refined")
    for name in ds["solution"].values:
        colour, label = styles.get(str(name), ("C2", str(name)))
        lon = ds["track_lon"].sel(solution=name).values
        lat = ds["track_lat"].sel(solution=name).values
        ax.plot(lon, lat, ".", ms=2, color=colour, label=label)
    ax.set_xlim(0, 360)
    ax.set_ylim(-90, 90)
    ax.set_xlabel("body-frame longitude of the phase vector [deg]")
    ax.set_ylabel("latitude [deg]")
    ax.set_title("observation tracks in the body frame")
    ax.legend(loc="lower left", fontsize=7, markerscale=4)
