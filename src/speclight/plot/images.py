"""Saved images: band-integrated radiance, DoLP (when polarised), depth map of each epoch."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from speclight.plot.compass import draw_compass
from speclight.plot.selection import band_radiance
from speclight.plot.style import epoch_summary, new_figure

# Most image epochs drawn in one figure; more would make rows too small to read.
MAX_IMAGE_ROWS = 6
# Dynamic range of the radiance colour scale (glints are orders brighter than diffuse parts).
RADIANCE_DYNAMIC_RANGE = 1e3


def _extent_m(ds: xr.Dataset, k: int, ny: int, nx: int) -> tuple[float, float, float, float]:
    pitch = float(ds["image_pixel_size"].values[k]) if "image_pixel_size" in ds else 1.0
    return (-nx * pitch / 2, nx * pitch / 2, -ny * pitch / 2, ny * pitch / 2)


def _on_target(ds: xr.Dataset, k: int, img: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Pixels that see the target: finite depth, else a part index >= 0, else radiance > 0."""
    if "image_depth" in ds:
        return np.isfinite(np.asarray(ds["image_depth"].isel(image_time=k).values, dtype=float))
    if "image_part" in ds:
        return np.asarray(ds["image_part"].isel(image_time=k).values) >= 0
    return np.asarray(img > 0)


def part_names(ds: xr.Dataset) -> list[str]:
    """Names of the target's parts, index order (from ``image_part``'s ``flag_meanings``)."""
    if "image_part" not in ds:
        return []
    return str(ds["image_part"].attrs.get("flag_meanings", "")).split()


def _draw_parts(fig: Any, ax: Any, ds: xr.Dataset, k: int) -> str:
    """Categorical map of the part seen in each pixel, with the part names on the colour bar."""
    from matplotlib import colormaps
    from matplotlib.colors import BoundaryNorm

    names = part_names(ds)
    parts = np.asarray(ds["image_part"].isel(image_time=k).values, dtype=float)
    parts[parts < 0] = np.nan
    cmap = colormaps["tab10"].resampled(max(len(names), 1)).with_extremes(bad="0.85")
    norm = BoundaryNorm(np.arange(len(names) + 1) - 0.5, cmap.N)
    im = ax.imshow(
        np.ma.masked_invalid(parts),
        cmap=cmap,
        norm=norm,
        interpolation="nearest",
        extent=_extent_m(ds, k, *parts.shape),
        origin="upper",
    )
    bar = fig.colorbar(im, ax=ax, ticks=np.arange(len(names)), shrink=0.85)
    bar.ax.set_yticklabels(names, fontsize="small")
    return "part seen\n(grey: off target)"


def _draw_dolp(fig: Any, ax: Any, ds: xr.Dataset, k: int, band: str | None) -> str:
    """Degree of linear polarisation ``sqrt(Q^2 + U^2) / I`` of the band-integrated Stokes
    images; pixels off the target or without signal (I <= 0) are masked (grey)."""
    from matplotlib import colormaps

    dolp = image_dolp(ds, k, band)
    finite = dolp[np.isfinite(dolp)]
    vmax = float(finite.max()) if finite.size and finite.max() > 0 else 1.0
    cmap = colormaps["cividis"].with_extremes(bad="0.85")
    im = ax.imshow(
        np.ma.masked_invalid(dolp),
        cmap=cmap,
        vmin=0.0,
        vmax=vmax,
        interpolation="nearest",
        extent=_extent_m(ds, k, *dolp.shape),
        origin="upper",
    )
    fig.colorbar(im, ax=ax, label="DoLP [1]", shrink=0.85)
    where = f"in {band}" if band else "whole grid"
    return f"degree of linear polarisation, {where}\n(grey: no signal)"


def image_dolp(ds: xr.Dataset, k: int, band: str | None) -> NDArray[np.float64]:
    """DoLP image (H, W) of saved image ``k`` over ``band`` (or the whole grid); NaN off the
    target and where the band-integrated radiance is not positive."""
    i = band_radiance(ds, k, band)
    q = band_radiance(ds, k, band, "image_radiance_q")
    u = band_radiance(ds, k, band, "image_radiance_u")
    ok = _on_target(ds, k, i) & (i > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(ok, np.hypot(q, u) / np.where(ok, i, 1.0), np.nan)


def _caption(names: list[str]) -> str:
    words = {"N": "N celestial north", "Z": "Z zenith", "☉": "☉ Sun"}
    return ", ".join(words[n] for n in names)


def images_figure(ds: xr.Dataset, band: str | None) -> Any:
    """One row per saved epoch (at most :data:`MAX_IMAGE_ROWS`, titled with the epoch's
    time and geometry): radiance in ``band`` (or the whole grid), its degree of linear
    polarisation (when the images carry Stokes Q, U: ``render.polarization``), depth map,
    and the part seen in each pixel (when the dataset names the parts).

    Pixel row 0 is the top of the image (the renderer's convention); axes are metres at
    the target, right and up as seen by the observer. The first image of each row carries a
    compass (:mod:`speclight.plot.compass`), in the corner that covers least of the
    target: celestial north (N), the observer's zenith (Z) and the Sun (☉) projected into
    the image plane, arrow length the sine of their angle to the line of sight.
    """
    from matplotlib import colormaps
    from matplotlib.colors import LogNorm

    n = ds.sizes["image_time"]
    shown = min(n, MAX_IMAGE_ROWS)
    polarised = "image_radiance" in ds and {"image_radiance_q", "image_radiance_u"} <= set(ds)
    columns = [c for c in ("image_radiance", "image_depth") if c in ds]
    if polarised:
        columns.insert(1, "image_dolp")
    if part_names(ds):
        columns.append("image_part")
    figure = new_figure(height_in=0.8 + 3.9 * shown, width_in=4.6 * len(columns) + 0.6)
    rows = np.atleast_1d(figure.subfigures(shown, 1))  # one per epoch, titled with it
    axes = [row.subplots(1, len(columns), squeeze=False)[0] for row in rows]
    image_epochs = np.atleast_1d(ds["image_time"].values)
    time = ds["time"].values
    name = ds.attrs.get("scenario_name", "speclight dataset")
    for k in range(shown):
        i = int(np.argmin(np.abs(time - image_epochs[k])))
        fig = rows[k]
        fig.suptitle(f"{name}: saved image {k + 1} of {n}, {epoch_summary(ds, i)}")
        for ax, col in zip(axes[k], columns, strict=True):
            if col in ("image_part", "image_dolp"):
                what = (
                    _draw_parts(fig, ax, ds, k)
                    if col == "image_part"
                    else _draw_dolp(fig, ax, ds, k, band)
                )
                ax.set_title(what, fontsize="small")
                ax.set_xlabel("right [m]")
                ax.set_ylabel("up [m]")
                continue
            if col == "image_radiance":
                img = band_radiance(ds, k, band)
                positive = img[np.isfinite(img) & (img > 0)]
                vmax = float(positive.max()) if positive.size else 1.0
                norm = LogNorm(vmin=vmax / RADIANCE_DYNAMIC_RANGE, vmax=vmax, clip=True)
                cmap = colormaps["inferno"].with_extremes(under="black", bad="0.85")
                data = np.ma.masked_invalid(np.where(_on_target(ds, k, img), img, np.nan))
                what = f"radiance in {band}" if band else "radiance, whole grid"
                what += "\n(grey: off target)"
                label = (
                    "∫ L R dλ [W m$^{-2}$ sr$^{-1}$]" if band else "∫ L dλ [W m$^{-2}$ sr$^{-1}$]"
                )
                im = ax.imshow(
                    data,
                    norm=norm,
                    cmap=cmap,
                    interpolation="nearest",
                    extent=_extent_m(ds, k, *img.shape),
                    origin="upper",
                )
            else:
                depth = np.asarray(ds["image_depth"].isel(image_time=k).values, dtype=float)
                cmap = colormaps["viridis"].with_extremes(bad="0.85")
                im = ax.imshow(
                    np.ma.masked_invalid(depth),
                    cmap=cmap,
                    interpolation="nearest",
                    extent=_extent_m(ds, k, *depth.shape),
                    origin="upper",
                )
                what = "depth\n(grey: off target)"
                label = "depth behind target centre [m]"
            fig.colorbar(
                im,
                ax=ax,
                label=label,
                shrink=0.85,
                extend="min" if col == "image_radiance" else "neither",
            )
            ax.set_title(what, fontsize="small")
            ax.set_xlabel("right [m]")
            ax.set_ylabel("up [m]")
        drawn = draw_compass(axes[k][0], ds, k, _on_target(ds, k, band_radiance(ds, k, band)))
        if drawn:
            axes[k][0].set_xlabel("right [m]; arrows: " + _caption(drawn))
    return figure
