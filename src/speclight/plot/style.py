"""Shared look of the figures: UTC time axes, band colours, unobservable-epoch shading.

Figures are built on :class:`matplotlib.figure.Figure` directly, never through
``pyplot``, so that plotting changes no process-wide matplotlib state (backend,
current figure) of the caller.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.schema import (  # the dataset's flag bits (CF flag_masks)
    FLAG_ATTITUDE_UNDEFINED,
    FLAG_BELOW_MIN_ELEVATION,
    FLAG_DAYLIGHT,
    FLAG_IN_SHADOW,
    FLAG_ORBIT_FAILED,
    FLAG_PENUMBRA,
    FLAG_RENDER_FAILED,
    NOT_OBSERVABLE,
)

DPI = 120
WIDTH_IN = 10.0

# Shading of epochs along time axes: (flag bits, face colour, legend label).
_SHADES = (
    (
        FLAG_ORBIT_FAILED
        | FLAG_BELOW_MIN_ELEVATION
        | FLAG_RENDER_FAILED
        | FLAG_ATTITUDE_UNDEFINED
        | FLAG_DAYLIGHT,
        "0.85",
        "not observable",
    ),
    (FLAG_IN_SHADOW, "#9aa7c7", "Earth shadow"),
    (FLAG_PENUMBRA, "#f3d9a4", "penumbra"),
)


def new_figure(height_in: float, width_in: float = WIDTH_IN) -> Any:
    """A constrained-layout figure that is not registered with pyplot."""
    try:
        from matplotlib.figure import Figure
    except ImportError as exc:  # pragma: no cover - matplotlib is a dependency
        raise InputError(
            "plotting needs matplotlib; install it with: pip install matplotlib", field="plot"
        ) from exc
    return Figure(figsize=(width_in, height_in), dpi=DPI, layout="constrained")


def flags(ds: xr.Dataset) -> NDArray[np.int64]:
    """The flag bits per epoch (zeros when the dataset has no ``flags``)."""
    if "flags" not in ds:
        return np.zeros(ds.sizes["time"], dtype=np.int64)
    return np.nan_to_num(ds["flags"].values).astype(np.int64)


def observable(ds: xr.Dataset) -> NDArray[np.bool_]:
    """Epochs above the minimum elevation, sunlit (penumbra allowed) and rendered."""
    return (flags(ds) & NOT_OBSERVABLE) == 0


def utc_label(ds: xr.Dataset) -> str:
    """Time-axis label naming the UTC date of the first epoch."""
    t = ds["time"].values
    day = np.datetime_as_string(t[0], unit="D") if t.size else ""
    return f"time [UTC] on {day}"


#: Room one ``HH:MM:SS`` tick label takes along the axis, with the gap to the next one
#: [em of the tick labels' font]: the label itself is about 4.5 em in DejaVu Sans (six
#: digits of 0.64 em, two colons of 0.34 em).
TIME_LABEL_PITCH_EM = 6.5


def set_time_ticks(ax: Any) -> None:
    """HH:MM:SS UTC ticks on the x axis of ``ax``, no more than fit side by side.

    The number of ticks is chosen when the axes are drawn, from their width then (after
    the layout), so the labels never run together (``02:20:0002:21:00`` on a 10-min pass).
    """
    import matplotlib.dates as mdates
    from matplotlib import rcParams
    from matplotlib.font_manager import FontProperties

    class FittingLocator(mdates.AutoDateLocator):
        def __call__(self) -> Any:
            axes = getattr(self.axis, "axes", None)  # None before the locator is on an axis
            if axes is not None:
                width_pt = axes.get_window_extent().width * 72.0 / axes.figure.dpi
                font = FontProperties(size=rcParams["xtick.labelsize"])
                fitting = int(width_pt / (TIME_LABEL_PITCH_EM * font.get_size_in_points()))
                self.maxticks = dict.fromkeys(self.maxticks, max(fitting, self.minticks))
            with warnings.catch_warnings():  # too narrow for any step: it takes the longest
                warnings.filterwarnings("ignore", "AutoDateLocator was unable", UserWarning)
                return super().__call__()

    locator = FittingLocator(minticks=3)
    # steps of 2 and 20 besides matplotlib's 1, 5, 10, 15, 30: 5 ticks on a 10-min pass
    locator.intervald[mdates.MINUTELY] = [1, 2, 5, 10, 15, 30]
    locator.intervald[mdates.SECONDLY] = [1, 2, 5, 10, 15, 20, 30]
    ax.xaxis.set_major_locator(locator)
    ax.xaxis.set_major_formatter(mdates.DateFormatter("%H:%M:%S"))


def format_time_axis(ax: Any, ds: xr.Dataset, label: bool = True) -> None:
    """HH:MM:SS UTC ticks (:func:`set_time_ticks`); the date goes in the label."""
    set_time_ticks(ax)
    if label:
        ax.set_xlabel(utc_label(ds))


def _runs(mask: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """(first, last) index of each run of True values."""
    if not mask.any():
        return []
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    starts = np.flatnonzero(edges == 1)
    stops = np.flatnonzero(edges == -1) - 1
    return list(zip(starts.tolist(), stops.tolist(), strict=True))


def shade_unobservable(ax: Any, ds: xr.Dataset) -> list[Any]:
    """Shade epochs that are not observable, in Earth shadow or in penumbra.

    Returns legend handles for the kinds of shading actually drawn.
    """
    from matplotlib.patches import Patch

    t = ds["time"].values
    if t.size == 0:
        return []
    half = (t[1] - t[0]) / 2 if t.size > 1 else np.timedelta64(500, "ms")
    f = flags(ds)
    handles = []
    for bits, colour, label in _SHADES:
        runs = _runs((f & bits) != 0)
        for i, j in runs:
            ax.axvspan(t[i] - half, t[j] + half, color=colour, alpha=0.6, lw=0, zorder=0)
        if runs:
            handles.append(Patch(color=colour, alpha=0.6, label=label))
    return handles


def band_centres_nm(ds: xr.Dataset) -> NDArray[np.float64]:
    """Response-weighted mean wavelength of each band [nm] (NaN when unknown)."""
    n = ds.sizes.get("band", 0)
    if "band_response" not in ds or "wavelength" not in ds.coords:
        return np.full(n, np.nan)
    r = np.nan_to_num(ds["band_response"].transpose("band", "wavelength").values)
    w = ds["wavelength"].values
    total = r.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(total > 0, (r * w).sum(axis=1) / total, np.nan)


#: Wavelength span of the band colour scale [nm].
COLOUR_SCALE_NM = (380.0, 1100.0)


def wavelength_colour_map() -> tuple[Any, Any]:
    """The colour map and normalisation [nm] that give each band its colour."""
    from matplotlib import colormaps
    from matplotlib.colors import ListedColormap, Normalize

    base = colormaps["turbo"]
    cmap = ListedColormap(base(np.linspace(0.05, 0.95, 256)), name="speclight_bands")
    return cmap, Normalize(*COLOUR_SCALE_NM)


def band_styles(ds: xr.Dataset) -> list[dict[str, Any]]:
    """Colour (by the band's mean wavelength, 380-1100 nm) and line style of each band.

    Bands whose mean wavelengths lie within 15 nm of an earlier band's get a dashed or
    dotted line so that they stay distinguishable.
    """
    from matplotlib import colormaps

    cmap, norm = wavelength_colour_map()
    centres = band_centres_nm(ds)
    n = centres.size
    styles: list[dict[str, Any]] = []
    dashes = ["-", "--", ":", "-."]
    for i, c in enumerate(centres):
        if np.isfinite(c):
            colour = cmap(float(np.clip(norm(c), 0.0, 1.0)))
            twins = int(np.sum(np.abs(centres[:i] - c) < 15.0))
        else:
            colour = colormaps["tab10"](i % 10)
            twins = 0
        styles.append({"color": colour, "ls": dashes[twins % len(dashes)]})
    return styles[:n]


def epoch_summary(ds: xr.Dataset, i: int) -> str:
    """One line describing epoch ``i``: UTC time, range, elevation, phase angle."""
    t = np.datetime_as_string(ds["time"].values[i], unit="s").replace("T", " ")
    parts = [f"{t} UTC"]
    for name, scale, fmt in (
        ("range", 1e-3, "range {:.0f} km"),
        ("elevation", 1.0, "elevation {:.1f}°"),
        ("phase_angle", 1.0, "phase angle {:.1f}°"),
    ):
        if name in ds:
            parts.append(fmt.format(float(ds[name].values[i]) * scale))
    return ", ".join(parts)
