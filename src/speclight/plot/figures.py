"""``speclight plot``: the figures a user looks at after a run."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from speclight.errors import InputError


def _pyplot() -> Any:
    try:
        import matplotlib
    except ImportError as exc:
        raise InputError(
            "plotting needs matplotlib: pip install 'speclight[plot]'", field="plot"
        ) from exc
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _geometry_axes(ds: xr.Dataset, axes: Any) -> None:
    t = ds["time"].values
    observable = (ds["flags"].values & 3) == 0 if "flags" in ds else np.ones(t.size, bool)
    panels = [
        ("range", 1e-3, "range [km]"),
        ("elevation", 1.0, "elevation [deg]"),
        ("phase_angle", 1.0, "phase angle [deg]"),
        ("sunlit", 1.0, "sunlit fraction"),
    ]
    for ax, (name, scale, label) in zip(axes, panels, strict=True):
        y = ds[name].values * scale
        ax.plot(t, y, color="0.7", lw=1)
        ax.plot(t, np.where(observable, y, np.nan), color="C0", lw=1.5)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        if name == "sunlit":
            ax.set_ylim(-0.05, 1.05)
    axes[-1].set_xlabel("time [UTC]")


def plot_dataset(ds: xr.Dataset) -> Any:
    """Build the figure for a dataset; returns the matplotlib figure."""
    plt = _pyplot()
    fig, axes = plt.subplots(4, 1, figsize=(9, 9), sharex=True, constrained_layout=True)
    _geometry_axes(ds, axes)
    name = ds.attrs.get("scenario_name", "")
    fig.suptitle(f"{name}: geometry along the pass (grey: below min. elevation)")
    fig.autofmt_xdate()
    return fig


def plot_file(dataset: str | Path, output: str | Path, force: bool = False) -> Path:
    """Read a dataset file and write its figure (atomically; ``force`` to overwrite)."""
    dataset, output = Path(dataset), Path(output)
    if output.exists() and not force:
        raise InputError(f"{output} exists; pass --force to overwrite it", field="--output")
    try:
        ds = xr.load_dataset(dataset, engine="h5netcdf")
    except (OSError, ValueError) as exc:
        raise InputError(f"cannot read {dataset} as a speclight dataset: {exc}") from exc
    missing = [n for n in ("range", "elevation", "phase_angle", "sunlit") if n not in ds]
    if missing:
        raise InputError(f"{dataset} lacks {', '.join(missing)}; is it a speclight output?")
    fig = plot_dataset(ds)
    fd, tmp = tempfile.mkstemp(prefix=f".{output.name}.", suffix=output.suffix, dir=output.parent)
    os.close(fd)
    try:
        fig.savefig(tmp, dpi=120)
        os.replace(tmp, output)
    finally:
        Path(tmp).unlink(missing_ok=True)
    return output
