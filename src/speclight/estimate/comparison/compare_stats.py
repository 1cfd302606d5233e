"""Residual statistics of ``speclight compare``: overall, per object and binned against phase
angle and elevation (CMP.nc, and the summary printed on the terminal).

Beside the residual's mean and RMS: Pearson's correlation coefficient R between observed
and simulated magnitudes (Pearson 1896, Phil. Trans. R. Soc. A 187, 253; as
``scipy.stats.pearsonr``), which Fankhauser et al. 2023 (arXiv:2305.11123, their
``model_correlation`` notebook) and Kandula et al. 2025 report for lumos-sat's models; and
the chi-square of docs/compare.md, ``sum((m_sim - m_obs)^2 / m_obs) / N`` over the
magnitudes themselves (Pearson's statistic with the observed magnitude as the expected
count, divided by the number of pairs), defined only where every observed magnitude is
> 0.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]
#: Bin edges of the binned statistics [deg].
PHASE_EDGES_DEG = np.arange(0.0, 181.0, 20.0)
#: Objects listed one per line on the terminal up to this many; beyond, their spread.
LISTED_OBJECTS = 10
#: Objects of largest RMS named on the terminal beyond :data:`LISTED_OBJECTS`.
WORST_OBJECTS = 5
ELEVATION_EDGES_DEG = np.arange(0.0, 91.0, 10.0)


def _summary(r: F64) -> tuple[int, float, float, float]:
    """Number, mean, RMS and median absolute value of the finite residuals."""
    r = r[np.isfinite(r)]
    if r.size == 0:
        return 0, np.nan, np.nan, np.nan
    return int(r.size), float(r.mean()), float(np.sqrt(np.mean(r**2))), float(np.median(np.abs(r)))


def pearson_r(x: F64, y: F64) -> float:
    """Pearson's R of the pairs where both are finite; NaN for fewer than two pairs or a
    constant ``x`` or ``y``."""
    ok = np.isfinite(x) & np.isfinite(y)
    if ok.sum() < 2:
        return np.nan
    dx, dy = x[ok] - x[ok].mean(), y[ok] - y[ok].mean()
    den = float(np.sqrt(np.sum(dx**2) * np.sum(dy**2)))
    if den == 0.0:
        return np.nan
    return float(np.clip(np.sum(dx * dy) / den, -1.0, 1.0))


def chi_square(observed: F64, simulated: F64) -> float:
    """``sum((simulated - observed)^2 / observed) / N`` over the pairs where both are finite;
    NaN where there is none or an observed magnitude is <= 0 (the statistic needs positive
    "counts")."""
    ok = np.isfinite(observed) & np.isfinite(simulated)
    if not ok.any() or np.any(observed[ok] <= 0.0):
        return np.nan
    return float(np.mean((simulated[ok] - observed[ok]) ** 2 / observed[ok]))


def agreement(observed: F64, simulated: F64) -> dict[str, float]:
    """``n``, ``mean``, ``rms``, ``median_abs`` of the residual observed - simulated [mag],
    ``pearson_r`` and ``chi_square`` of one set of pairs."""
    n, mean, rms, med = _summary(observed - simulated)
    return {
        "n": n,
        "mean": mean,
        "rms": rms,
        "median_abs": med,
        "pearson_r": pearson_r(observed, simulated),
        "chi_square": chi_square(observed, simulated),
    }


def per_object(
    observed: F64, simulated: F64, object_index: NDArray[np.intp], n_objects: int
) -> dict[str, F64]:
    """:func:`agreement` of each object's pairs: arrays (n_objects,) per key."""
    out = {
        k: np.full(n_objects, np.nan)
        for k in ("n", "mean", "rms", "median_abs", "pearson_r", "chi_square")
    }
    order = np.argsort(object_index, kind="stable")
    bounds = np.searchsorted(object_index[order], np.arange(n_objects + 1))
    for j in range(n_objects):
        rows = order[bounds[j] : bounds[j + 1]]
        for k, v in agreement(observed[rows], simulated[rows]).items():
            out[k][j] = v
    return out


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


def residual_statistics(
    observed: F64, simulated: F64, phase_angle_deg: F64, elevation_deg: F64
) -> dict[str, Any]:
    """The attributes of CMP.nc: ``residual_n``, ``residual_mean_mag``, ``residual_rms_mag``,
    ``residual_median_abs_mag``, ``pearson_r``, ``chi_square``, and per bin of phase angle
    and elevation (edges in ``phase_angle_bin_edges_deg``, ``elevation_bin_edges_deg``)
    ``..._n``, ``..._mean_mag``, ``..._rms_mag``. Only finite residuals count (an
    unobservable epoch has none)."""
    residual = np.asarray(observed, dtype=float) - np.asarray(simulated, dtype=float)
    a = agreement(np.asarray(observed, dtype=float), np.asarray(simulated, dtype=float))
    out: dict[str, Any] = {
        "residual_n": a["n"],
        "residual_mean_mag": a["mean"],
        "residual_rms_mag": a["rms"],
        "residual_median_abs_mag": a["median_abs"],
        "pearson_r": a["pearson_r"],
        "chi_square": a["chi_square"],
    }
    for name, x, edges in (
        ("phase_angle", phase_angle_deg, PHASE_EDGES_DEG),
        ("elevation", elevation_deg, ELEVATION_EDGES_DEG),
    ):
        b = binned(residual, np.asarray(x, dtype=float), edges)
        out[f"{name}_bin_edges_deg"] = edges
        out[f"residual_by_{name}_n"] = b["n"].astype(np.int64)
        out[f"residual_by_{name}_mean_mag"] = b["mean"]
        out[f"residual_by_{name}_rms_mag"] = b["rms"]
    return out


def _r_and_chi(r: float, chi: float) -> str:
    r_text = f"Pearson R {r:.3f}" if np.isfinite(r) else "Pearson R n/a (< 2 pairs or constant)"
    chi_text = f"chi-square {chi:.4f}" if np.isfinite(chi) else "chi-square n/a (a magnitude <= 0)"
    return f"{r_text}, {chi_text}"


def summary_lines(ds: Any) -> list[str]:
    """The statistics of a CMP.nc dataset as lines for the terminal: overall, per bin and,
    where the file has objects, per object (one line each up to :data:`LISTED_OBJECTS`,
    else their spread and the worst)."""
    attrs = ds.attrs
    lines = [
        f"residual (observed - simulated) over {attrs['residual_n']} observations: mean "
        f"{attrs['residual_mean_mag']:+.3f} mag, RMS {attrs['residual_rms_mag']:.3f} mag, "
        f"median |r| {attrs['residual_median_abs_mag']:.3f} mag; "
        + _r_and_chi(attrs["pearson_r"], attrs["chi_square"])
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
    if "object" in ds.dims:
        lines += _object_lines(ds)
    return lines


def _object_lines(ds: Any) -> list[str]:
    names = [str(o) for o in ds["object"].values]
    n = ds["n_per_object"].values
    rms = ds["residual_rms_per_object"].values
    if len(names) <= LISTED_OBJECTS:
        return [
            f"object {name}: no residual (not observable at any of its rows)"
            if n[j] == 0
            else f"object {name}: n {int(n[j])}, mean "
            f"{ds['residual_mean_per_object'].values[j]:+.3f} mag, RMS {rms[j]:.3f} mag; "
            + _r_and_chi(
                ds["pearson_r_per_object"].values[j], ds["chi_square_per_object"].values[j]
            )
            for j, name in enumerate(names)
        ]
    has = n > 0
    if not has.any():
        return [f"{len(names)} objects, none with a residual"]
    lo, mid, hi = np.percentile(rms[has], [10, 50, 90])
    r = ds["pearson_r_per_object"].values
    r_median = f"{np.nanmedian(r):.3f}" if np.isfinite(r).any() else "n/a"
    worst = np.argsort(np.where(has, -rms, np.inf), kind="stable")[:WORST_OBJECTS]
    return [
        f"{len(names)} objects, {int(has.sum())} with residuals: RMS per object median "
        f"{mid:.3f} mag (10-90 %: {lo:.3f}-{hi:.3f}); Pearson R per object median "
        f"{r_median} "
        f"({int(np.isfinite(r).sum())} objects with >= 2 pairs)",
        "largest RMS: "
        + ", ".join(f"{names[j]} {rms[j]:.3f} mag (n {int(n[j])})" for j in worst if has[j]),
    ]
