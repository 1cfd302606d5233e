"""Figure of ``speclight unmix``, drawn from its ABUND.nc dataset.

Panels: the contributions per endmember against time; the endmember signatures per band
(at the bands' photon-weighted centres; extracted signatures, which are reflectance
factors, divided by their band mean, beside the ground-truth signatures when the input had
them: the reference paper's Figure 14). With ground truth, also the true and estimated
fractions of the contributions against time and the confusion matrix of the dominant
material (the reference paper's Figure 13).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from speclight.estimate.spectra.upsampling import photon_weights
from speclight.plot.style import new_figure


def _colours(n: int) -> list[Any]:
    from matplotlib import colormaps

    cmap = colormaps["tab10"]
    return [cmap(i % 10) for i in range(n)]


def _band_centres(ds: xr.Dataset) -> np.ndarray:
    wl = ds["wavelength"].values
    w = photon_weights(ds["band_response"].transpose("band", "wavelength").values, wl)
    return np.asarray(w @ wl)


def abundance_panel(ds: xr.Dataset, ax: Any) -> None:
    """Contribution of each endmember against time."""
    a = ds["abundance"].transpose("time", "endmember").values
    t = ds["time"].values
    for k, (name, c) in enumerate(zip(ds["endmember"].values, _colours(a.shape[1]), strict=True)):
        ax.plot(t, a[:, k], lw=1.2, color=c, label=str(name))
    units = ds["abundance"].attrs.get("units", "")
    ax.set_ylabel(f"abundance [{units}]")
    ax.set_xlabel("time (UTC)")
    ax.set_title(f"contributions ({ds.attrs.get('method', '')})", loc="left", fontsize="medium")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small", framealpha=0.8)
    ax.tick_params(axis="x", labelrotation=20)


def signature_panel(ds: xr.Dataset, ax: Any) -> None:
    """Endmember signatures per band; extracted ones normalised, with the true ones."""
    x = _band_centres(ds)
    order = np.argsort(x)
    s = ds["endmember_signature"].transpose("endmember", "band").values
    extracted = ds["endmember_signature"].attrs.get("units") != "1"
    if extracted:
        mean = s.mean(axis=1, keepdims=True)
        s = s / np.where(mean != 0, mean, 1.0)
    for k, (name, c) in enumerate(zip(ds["endmember"].values, _colours(s.shape[0]), strict=True)):
        label = str(name)
        if "endmember_material" in ds:
            label += f" ~ {ds['endmember_material'].values[k]}"
            label += f" ({float(ds['endmember_angle'].values[k]):.1f} deg)"
        ax.plot(x[order], s[k, order], "o-", color=c, ms=4, lw=1.2, label=label)
    if extracted and "true_signature" in ds:
        for m, name in enumerate(ds["class"].values):
            sig = ds["true_signature"].transpose("class", "band").values[m]
            ax.plot(x[order], sig[order], "--", color="0.4", lw=1.0)
            ax.annotate(
                str(name),
                (x[order][-1], sig[order][-1]),
                fontsize="x-small",
                color="0.3",
                xytext=(3, 0),
                textcoords="offset points",
            )
        ax.plot([], [], "--", color="0.4", label="true signatures (dashed)")
    ax.set_xlabel("band centre (photon-weighted) [nm]")
    ax.set_ylabel("signature / band mean [1]" if extracted else "band reflectance [1]")
    what = "extracted signatures" if extracted else "endmember signatures"
    ax.set_title(what, loc="left", fontsize="medium")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small", framealpha=0.8)


def share_panel(ds: xr.Dataset, ax: Any) -> None:
    """True (solid) and estimated (dots) fractions of each class against time."""
    t = ds["time"].values
    true = ds["true_share"].transpose("time", "class").values
    est = ds["estimated_share"].transpose("time", "class").values
    for c, (name, col) in enumerate(zip(ds["class"].values, _colours(true.shape[1]), strict=True)):
        ax.plot(t, true[:, c], "-", color=col, lw=1.4, label=f"{name}")
        ax.plot(t, est[:, c], ".", color=col, ms=2.5)
    ax.plot([], [], ".", color="0.3", label="estimated (dots)")
    ax.set_ylabel("fraction of the contributions [1]")
    ax.set_xlabel("time (UTC)")
    err = ds.attrs.get("mean_absolute_share_error", float("nan"))
    ax.set_title(
        f"true (lines) and estimated shares; mean |error| {err:.3f}", loc="left", fontsize="medium"
    )
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small", framealpha=0.8)
    ax.tick_params(axis="x", labelrotation=20)


def confusion_panel(ds: xr.Dataset, ax: Any) -> None:
    """Row-normalised confusion matrix of the dominant class (paper Figure 13)."""
    cm = ds["confusion_matrix"].values
    count = ds["confusion_count"].values if "confusion_count" in ds else None
    names = [str(c) for c in ds["class"].values]
    ax.imshow(np.nan_to_num(cm, nan=0.0), cmap="Blues", vmin=0.0, vmax=1.0)
    for i in range(cm.shape[0]):
        for j in range(cm.shape[1]):
            text = "-" if not np.isfinite(cm[i, j]) else f"{cm[i, j]:.2f}"
            if count is not None and np.isfinite(cm[i, j]):
                text += f"\n({count[i, j]})"
            dark = np.isfinite(cm[i, j]) and cm[i, j] > 0.6
            ax.text(
                j,
                i,
                text,
                ha="center",
                va="center",
                fontsize="small",
                color="white" if dark else "black",
            )
    ax.set_xticks(range(len(names)), names, rotation=30, ha="right", fontsize="small")
    ax.set_yticks(range(len(names)), names, fontsize="small")
    ax.set_xlabel("estimated dominant material")
    ax.set_ylabel("true dominant material")
    ax.set_title(
        f"confusion matrix (matched {ds.attrs.get('matching', '')})", loc="left", fontsize="small"
    )


def unmix_figure(ds: xr.Dataset) -> Any:
    """The figure of an ABUND.nc dataset (module doc).

    Returns
    -------
    matplotlib.figure.Figure
    """
    truth = "confusion_matrix" in ds
    fig = new_figure(8.0 if truth else 4.2, 12.0)
    if truth:
        axes = fig.subplots(2, 2, gridspec_kw={"width_ratios": [1.5, 1.0]})
        abundance_panel(ds, axes[0, 0])
        signature_panel(ds, axes[0, 1])
        share_panel(ds, axes[1, 0])
        confusion_panel(ds, axes[1, 1])
    else:
        axes = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.5, 1.0]})
        abundance_panel(ds, axes[0])
        signature_panel(ds, axes[1])
    return fig
