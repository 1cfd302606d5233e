"""Geometry panels along the pass: range, elevation, phase angle, sunlit fraction."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import xarray as xr

from speclight.plot.style import observable, shade_unobservable

# (variable, scale to the plotted unit, axis label)
PANELS = (
    ("range", 1e-3, "range\n[km]"),
    ("elevation", 1.0, "elevation\n[deg]"),
    ("phase_angle", 1.0, "phase angle\n[deg]"),
    ("sunlit", 1.0, "sunlit\nfraction [1]"),
)


def geometry_panels(ds: xr.Dataset, axes: Sequence[Any]) -> None:
    """Draw the four geometry panels on ``axes`` (four axes sharing a time axis).

    Observable epochs are drawn in colour over a grey line for the whole pass; epochs
    that are not observable, in the Earth's shadow or in penumbra are shaded.
    """
    t = ds["time"].values
    ok = observable(ds)
    handles: list[Any] = []
    for ax, (name, scale, label) in zip(axes, PANELS, strict=True):
        handles = shade_unobservable(ax, ds)
        y = np.asarray(ds[name].values, dtype=np.float64) * scale
        ax.plot(t, y, color="0.55", lw=1.0, label="whole pass")
        ax.plot(t, np.where(ok, y, np.nan), color="C0", lw=1.8, label="observable")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        if name == "sunlit":
            ax.set_ylim(-0.05, 1.05)
        if name == "elevation" and "min_elevation_deg" in ds.attrs:
            limit = float(ds.attrs["min_elevation_deg"])
            ax.axhline(limit, color="0.3", ls=":", lw=1)
            ax.legend(
                [ax.get_lines()[-1]], [f"min. elevation {limit:g}°"], loc="best", fontsize="small"
            )
    lines = axes[0].get_lines()[:2]
    axes[0].legend(
        [*lines, *handles],
        [*(str(x.get_label()) for x in lines), *(str(h.get_label()) for h in handles)],
        loc="best",
        fontsize="small",
        ncols=2,
    )
