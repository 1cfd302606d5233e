"""The main figure: light curves, spectrogram and geometry on one UTC time axis."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from speclight.plot.geometry_panels import PANELS, geometry_panels
from speclight.plot.laser_panels import laser_panel, laser_rows
from speclight.plot.lightcurve import MAGNITUDES, count_rate_panel, magnitude_panel
from speclight.plot.polarization_panel import dolp_panel, has_polarization
from speclight.plot.selection import has_bands, has_spectra
from speclight.plot.spectrogram import spectrogram_panel
from speclight.plot.style import format_time_axis, new_figure


def overview_figure(ds: xr.Dataset, epoch: int | None = None, magnitude: str = "ab") -> Any:
    """Light curve per band, polarisation (with ``dolp``), spectrogram, laser returns (with
    lasers) and geometry.

    ``magnitude``: the magnitudes shown (:data:`~speclight.plot.lightcurve.MAGNITUDES`: AB at
    the aperture, above the atmosphere, at 1000 km, or Vega V).

    Panels that the dataset cannot fill (no bands, no wavelength grid) are left out, so a
    geometry-only dataset gives the four geometry panels. ``epoch`` (the one the chain
    figure follows) is marked by a dashed line, saved image epochs by dotted ones.
    """
    rows: list[tuple[str, float]] = []
    if has_bands(ds):
        if "count_rate" in ds:
            rows.append(("count_rate", 2.2))
        if MAGNITUDES[magnitude][0] in ds:
            rows.append(("ab_magnitude", 1.8))
        if has_polarization(ds):
            rows.append(("dolp", 1.6))
    if has_spectra(ds):
        rows.append(("spectrogram", 2.4))
    lasers = laser_rows(ds)
    rows += lasers
    rows += [(name, 1.3) for name, _, _ in PANELS]
    ratios = [h for _, h in rows]
    fig = new_figure(height_in=1.0 + sum(ratios))
    axes = fig.subplots(len(rows), 1, sharex=True, gridspec_kw={"height_ratios": ratios})
    by_name = dict(zip([n for n, _ in rows], axes, strict=True))
    if "count_rate" in by_name:
        count_rate_panel(ds, by_name["count_rate"])
    if "ab_magnitude" in by_name:
        magnitude_panel(ds, by_name["ab_magnitude"], magnitude)
    if "dolp" in by_name:
        dolp_panel(ds, by_name["dolp"])
    if "spectrogram" in by_name:
        mesh, label = spectrogram_panel(ds, by_name["spectrogram"])
        cax = by_name["spectrogram"].inset_axes((1.015, 0.0, 0.018, 1.0))
        fig.colorbar(mesh, cax=cax, label=label, extend="min")
    for name, _ in lasers:
        laser_panel(ds, name, by_name[name])
    geometry_panels(ds, [by_name[name] for name, _, _ in PANELS])
    _mark_epochs(ds, axes, epoch)
    for ax in axes[:-1]:
        ax.tick_params(labelbottom=False)
    format_time_axis(axes[-1], ds)
    fig.align_ylabels(axes)
    name = ds.attrs.get("scenario_name", "speclight dataset")
    parts = (["light curves"] if has_bands(ds) else []) + (["spectrum"] if has_spectra(ds) else [])
    parts += ["laser returns"] if lasers else []
    what = f"{', '.join(parts)} and geometry" if parts else "geometry"
    fig.suptitle(f"{name}: {what} along the pass")
    return fig


def _mark_epochs(ds: xr.Dataset, axes: Any, epoch: int | None) -> None:
    t = ds["time"].values
    marks: list[tuple[Any, str]] = []
    if epoch is not None:
        marks.append((t[epoch], "--"))
    if "image_time" in ds.coords:
        marks += [(ti, ":") for ti in np.atleast_1d(ds["image_time"].values)]
    for ax in axes:
        for when, ls in marks:
            ax.axvline(when, color="k", ls=ls, lw=0.9, alpha=0.7)
    if marks:
        labels = []
        if epoch is not None:
            labels.append("dashed: epoch of the chain figure")
        if "image_time" in ds.coords:
            labels.append("dotted: saved images")
        axes[-1].annotate(
            "; ".join(labels),
            xy=(1.0, -0.55),
            xycoords="axes fraction",
            ha="right",
            va="top",
            fontsize="small",
        )
