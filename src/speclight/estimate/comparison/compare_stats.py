"""Residual statistics of ``speclight compare``: overall and binned against phase angle and
elevation (CMP.nc attributes, and the summary printed on the terminal)."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]
#: Bin edges of the binned statistics [deg].
PHASE_EDGES_DEG = np.arange(0.0, 181.0, 20.0)
ELEVATION_EDGES_DEG = np.arange(0.0, 91.0, 10.0)


def _summary(r: F64) -> tuple[int, float, float, float]:
    """Number, mean, RMS and median absolute value of the finite residuals."""
    r = r[np.isfinite(r)]
    if r.size == 0:
        return 0, np.nan, np.nan, np.nan
    return int(r.size), float(r.mean()), float(np.sqrt(np.mean(r**2))), float(np.median(np.abs(r)))


def binned(residual: F64, x: F64, edges: F64) -> dict[str, F64]:
    """Number, mean and RMS of the finite residuals in each bin ``edges[i] <= x < edges[i+1]``
    (the last bin includes its upper edge); NaN for an empty bin."""
    nbin = edges.size - 1
    k = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, nbin - 1)
    inside = np.isfinite(residual) & (x >= edges[0]) & (x <= edges[-1])
    n = np.zeros(nbin)
    mean = np.full(nbin, np.nan)
    rms = np.full(nbin, np.nan)
    for b in range(nbin):
        r = residual[inside & (k == b)]
        n[b] = r.size
        if r.size:
            mean[b] = r.mean()
            rms[b] = np.sqrt(np.mean(r**2))
    return {"n": n, "mean": mean, "rms": rms}


def residual_statistics(residual: F64, phase_angle_deg: F64, elevation_deg: F64) -> dict[str, Any]:
    """The attributes of CMP.nc: ``residual_n``, ``residual_mean_mag``, ``residual_rms_mag``,
    ``residual_median_abs_mag``, and per bin of phase angle and elevation (edges in
    ``phase_angle_bin_edges_deg``, ``elevation_bin_edges_deg``) ``..._n``, ``..._mean_mag``,
    ``..._rms_mag``. Only finite residuals count (an unobservable epoch has none)."""
    n, mean, rms, med = _summary(np.asarray(residual, dtype=float))
    out: dict[str, Any] = {
        "residual_n": n,
        "residual_mean_mag": mean,
        "residual_rms_mag": rms,
        "residual_median_abs_mag": med,
    }
    for name, x, edges in (
        ("phase_angle", phase_angle_deg, PHASE_EDGES_DEG),
        ("elevation", elevation_deg, ELEVATION_EDGES_DEG),
    ):
        b = binned(np.asarray(residual, dtype=float), np.asarray(x, dtype=float), edges)
        out[f"{name}_bin_edges_deg"] = edges
        out[f"residual_by_{name}_n"] = b["n"].astype(np.int64)
        out[f"residual_by_{name}_mean_mag"] = b["mean"]
        out[f"residual_by_{name}_rms_mag"] = b["rms"]
    return out


def summary_lines(attrs: dict[str, Any]) -> list[str]:
    """The statistics as lines for the terminal."""
    lines = [
        f"residual (observed - simulated) over {attrs['residual_n']} observations: mean "
        f"{attrs['residual_mean_mag']:+.3f} mag, RMS {attrs['residual_rms_mag']:.3f} mag, "
        f"median |r| {attrs['residual_median_abs_mag']:.3f} mag"
    ]
    for name, label in (("phase_angle", "phase angle"), ("elevation", "elevation")):
        edges = attrs[f"{name}_bin_edges_deg"]
        cells = []
        for i, count in enumerate(attrs[f"residual_by_{name}_n"]):
            if count:
                mean = attrs[f"residual_by_{name}_mean_mag"][i]
                rms = attrs[f"residual_by_{name}_rms_mag"][i]
                cells.append(
                    f"{edges[i]:g}-{edges[i + 1]:g}: {mean:+.3f} / {rms:.3f} (n {int(count)})"
                )
        lines.append(f"by {label} [deg] (mean / RMS mag): " + ("; ".join(cells) or "none"))
    return lines
