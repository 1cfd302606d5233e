"""Figure of ``speclight reflection-map``, drawn from its RMAP.nc dataset.

Mollweide projections of the body-frame sphere (longitude from +x towards +y, +z at the
top), like the reference paper's Figures 16-17 (Nussbaum et al. 2022, section 5.3): the
reflectance factor of one band, the number of samples per pixel, the mean range offset where
the input had ranging, and each endmember's contribution where the pixels were unmixed; the
observed track of the phase vector (or of the observer direction under coaxial lasers) in
white over each. The HEALPix map is resampled on a regular longitude-latitude grid
(astropy-healpix's ``lonlat_to_healpix``) for drawing.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from speclight.errors import InputError, did_you_mean
from speclight.plot.style import new_figure

#: Cells of the drawing grid per degree (at least; finer for fine maps).
CELLS_PER_DEG = 1


def _grid(nside: int) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
    """Cell edges in longitude and latitude [rad] and the RING pixel of each cell centre."""
    import astropy.units as u
    from astropy_healpix import lonlat_to_healpix

    per_deg = max(CELLS_PER_DEG, int(np.ceil(nside / 32)))
    lon_e = np.radians(np.linspace(-180.0, 180.0, 360 * per_deg + 1))
    lat_e = np.radians(np.linspace(-90.0, 90.0, 180 * per_deg + 1))
    lon_c, lat_c = np.meshgrid(0.5 * (lon_e[1:] + lon_e[:-1]), 0.5 * (lat_e[1:] + lat_e[:-1]))
    pix = lonlat_to_healpix(lon_c * u.rad, lat_c * u.rad, nside, order="ring")
    return lon_e, lat_e, np.asarray(pix, dtype=np.int64)


def _track(ds: xr.Dataset) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Longitude and latitude [rad] of the track, NaN-broken where it wraps at +-180 deg."""
    d = ds["track_direction_body"].transpose("time", "xyz").values
    d = d[ds["track_pixel"].values >= 0]
    lon = np.arctan2(d[:, 1], d[:, 0])
    lat = np.arcsin(np.clip(d[:, 2], -1.0, 1.0))
    jumps = np.flatnonzero(np.abs(np.diff(lon)) > np.pi) + 1
    return np.insert(lon, jumps, np.nan), np.insert(lat, jumps, np.nan)


def _panel(ax: Any, grid: tuple, values: NDArray[np.float64], track: tuple, title: str) -> Any:
    from matplotlib import colormaps

    lon_e, lat_e, pix = grid
    image = np.ma.masked_invalid(values[pix])
    cmap = colormaps["viridis"].with_extremes(bad="0.85")
    mesh = ax.pcolormesh(lon_e, lat_e, image, cmap=cmap, shading="flat", rasterized=True)
    ax.plot(*track, color="white", lw=0.6, alpha=0.8)
    ax.set_title(title, fontsize="medium")
    ax.grid(alpha=0.4)
    ax.tick_params(labelsize="x-small")
    return mesh


def choose_band(ds: xr.Dataset, band: str | None) -> int:
    """Index of ``band`` (default: the band with the most mapped pixels, the first of ties)."""
    names = [str(b) for b in ds["band"].values]
    if band is None:
        return int(np.argmax(np.isfinite(ds["reflectance_factor"].values).sum(axis=1)))
    if band not in names:
        raise InputError(
            f"unknown band '{band}'{did_you_mean(band, names)} (choices: {', '.join(names)})",
            field="--band",
        )
    return names.index(band)


def reflection_map_figure(ds: xr.Dataset, band: str | None = None) -> Any:
    """Mollweide maps of an RMAP.nc dataset (module doc) for ``band`` (default: the first
    band with the most mapped pixels)."""
    j = choose_band(ds, band)
    name = str(ds["band"].values[j])
    panels: list[tuple[NDArray[np.float64], str, str]] = [
        (ds["reflectance_factor"].values[j], f"reflectance factor, {name}", "m2 sr-1"),
        (np.where(ds["n_samples"].values > 0, ds["n_samples"].values, np.nan), "samples", "1"),
    ]
    if "range_offset" in ds:
        panels.append((ds["range_offset"].values[j], f"mean range offset, {name}", "m"))
    if "abundance" in ds:
        unit = ds["abundance"].attrs.get("units", "")
        for k, member in enumerate(ds["endmember"].values):
            panels.append((ds["abundance"].values[k], f"contribution: {member}", unit))
    ncols = 2
    nrows = (len(panels) + ncols - 1) // ncols
    fig = new_figure(3.1 * nrows + 0.4, 11.0)
    grid = _grid(int(ds.attrs["healpix_nside"]))
    track = _track(ds)
    for i, (values, title, unit) in enumerate(panels):
        ax = fig.add_subplot(nrows, ncols, i + 1, projection="mollweide")
        mesh = _panel(ax, grid, np.asarray(values, dtype=float), track, title)
        fig.colorbar(mesh, ax=ax, shrink=0.7, label=f"[{unit}]")
    what = "phase vector" if ds.attrs.get("light") == "sun" else "observer direction (lasers)"
    fig.suptitle(
        f"reflection map, body frame (HEALPix nside {ds.attrs['healpix_nside']}); "
        f"white: track of the {what}",
        fontsize="medium",
    )
    return fig
