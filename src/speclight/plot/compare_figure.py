"""Figure of ``speclight compare``: residuals against time and phase angle, and where the
Sun and the observer were in the body frame, coloured by the residual."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from speclight.plot.style import new_figure


def _lon_lat_deg(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Body-frame longitude (atan2(y, x)) and latitude (asin z) of unit vectors [deg]."""
    lon = np.degrees(np.arctan2(v[:, 1], v[:, 0]))
    lat = np.degrees(np.arcsin(np.clip(v[:, 2], -1.0, 1.0)))
    return lon, lat


def compare_figure(ds: xr.Dataset) -> Any:
    """The figure (a matplotlib ``Figure``) of a CMP.nc dataset."""
    fig = new_figure(7.5)
    (ax_t, ax_p), (ax_s, ax_o) = fig.subplots(2, 2)
    r = ds["residual"].values.astype(float)
    ok = np.isfinite(r)
    lim = float(np.nanmax(np.abs(r))) if ok.any() else 1.0
    bands = [str(b) for b in ds["band"].values]
    for name in dict.fromkeys(bands):
        sel = ok & (np.array(bands) == name)
        ax_t.plot(ds["time"].values[sel], r[sel], ".", ms=3, label=name)
        ax_p.plot(ds["phase_angle"].values[sel], r[sel], ".", ms=3, label=name)
    for ax in (ax_t, ax_p):
        ax.axhline(0.0, color="0.5", lw=0.8)
        ax.set_ylabel("observed - simulated [mag]")
        ax.invert_yaxis()  # up: brighter than simulated
    ax_t.set_xlabel("time [UTC]")
    ax_t.tick_params(axis="x", labelrotation=30)
    ax_p.set_xlabel("phase angle [deg]")
    ax_p.legend(fontsize="small", frameon=False)
    scatter = None
    for ax, name, title in (
        (ax_s, "sun_direction_body", "Sun direction, body frame"),
        (ax_o, "observer_direction_body", "observer direction, body frame"),
    ):
        lon, lat = _lon_lat_deg(ds[name].values[ok])
        scatter = ax.scatter(lon, lat, c=r[ok], s=6, cmap="coolwarm", vmin=-lim, vmax=lim)
        ax.set_xlim(-180, 180)
        ax.set_ylim(-90, 90)
        ax.set_xlabel("longitude atan2(y, x) [deg]")
        ax.set_ylabel("latitude asin(z) [deg]")
        ax.set_title(title, fontsize="medium")
    if scatter is not None:
        fig.colorbar(scatter, ax=[ax_s, ax_o], label="observed - simulated [mag]")
    a = ds.attrs
    fig.suptitle(
        f"{a['residual_n']} observations: mean {a['residual_mean_mag']:+.3f} mag, RMS "
        f"{a['residual_rms_mag']:.3f} mag",
        fontsize="medium",
    )
    return fig
