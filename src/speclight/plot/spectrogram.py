"""Spectrogram: time x wavelength of the spectral flux at the aperture (log colours)."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

# Dynamic range of the colour scale: fainter bins (deep UV, absorption band cores) saturate
# to the bottom colour so that the pass's structure stays visible.
DYNAMIC_RANGE = 1e4


def spectrogram_panel(ds: xr.Dataset, ax: Any) -> tuple[Any, str]:
    """Draw the spectrogram on ``ax``; returns the mappable and label for a colour bar.

    Uses ``spectral_flux`` [W nm-1]; a dataset without it shows ``intensity``
    [W sr-1 nm-1] instead. Zero (unlit) and NaN (not observable) cells are grey.
    """
    from matplotlib import colormaps
    from matplotlib.colors import LogNorm

    name = "spectral_flux" if "spectral_flux" in ds else "intensity"
    z = ds[name].transpose("wavelength", "time").values.astype(np.float64)
    positive = z[np.isfinite(z) & (z > 0)]
    vmax = float(positive.max()) if positive.size else 1.0
    norm = LogNorm(vmin=vmax / DYNAMIC_RANGE, vmax=vmax, clip=True)
    cmap = colormaps["magma"].with_extremes(bad="0.8")
    masked = np.ma.masked_where(~(np.isfinite(z) & (z > 0)), z)
    mesh = ax.pcolormesh(
        ds["time"].values,
        ds["wavelength"].values,
        masked,
        norm=norm,
        cmap=cmap,
        shading="nearest",
        rasterized=True,
    )
    ax.set_ylabel("wavelength [nm]")
    what = "spectral flux at the aperture" if name == "spectral_flux" else "radiant intensity"
    ax.set_title(f"spectrogram: {what} (grey: no signal)", loc="left", fontsize="medium")
    label = (
        "spectral flux [W nm$^{-1}$]"
        if name == "spectral_flux"
        else "intensity [W sr$^{-1}$ nm$^{-1}$]"
    )
    return mesh, label
