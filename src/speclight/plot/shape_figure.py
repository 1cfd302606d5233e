"""Figure of ``speclight shape``: period scan, pole map, three views of the shape, fits.

Top row: chi-square against trial period (the best marked); the pole map (chi-square with
the pole held, ecliptic longitude and latitude, the best and the mirror marked); bottom
rows: the polyhedron seen along the body's x, y and z axes (z is the spin axis), shaded by
the facets' tilt; then every light curve against time with the fit.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from speclight.estimate.shape.minkowski import Polyhedron, minkowski_polyhedron
from speclight.plot.style import new_figure

#: Light-curve panels per row.
CURVES_PER_ROW = 4
VIEWS = (("x", (1, 2)), ("y", (0, 2)), ("z (spin axis)", (0, 1)))


def _shape_views(fig: Any, grid: Any, poly: Polyhedron | None) -> None:
    from matplotlib.collections import PolyCollection

    for k, (axis, (i, j)) in enumerate(VIEWS):
        ax = fig.add_subplot(grid[1, k])
        ax.set_aspect("equal")
        ax.set_title(f"seen along {axis}", fontsize="small")
        if poly is None:
            ax.text(
                0.5,
                0.5,
                "no shape (data do not constrain one)",
                ha="center",
                va="center",
                transform=ax.transAxes,
                fontsize="small",
            )
            continue
        tri = poly.vertices[poly.faces]
        normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        normal /= np.linalg.norm(normal, axis=1, keepdims=True)
        view = np.zeros(3)
        view[3 - i - j] = 1.0
        facing = normal @ view > 0
        shade = np.clip(normal[facing] @ view, 0.0, 1.0)
        col = PolyCollection(
            list(tri[facing][:, :, [i, j]]),
            facecolors=[(s, s, s) for s in 0.2 + 0.7 * shade],
            edgecolors="none",
        )
        ax.add_collection(col)
        lim = 1.05 * np.max(np.abs(poly.vertices))
        ax.set_xlim(-lim, lim)
        ax.set_ylim(-lim, lim)
        ax.set_xlabel("xyz"[i])
        ax.set_ylabel("xyz"[j])


def shape_figure(ds: xr.Dataset, poly: Polyhedron | None = None) -> Any:
    """The figure of a SHAPE.nc dataset (module doc). ``poly``: the polyhedron (default:
    rebuilt from the dataset's EGI when the shape is constrained).

    Returns
    -------
    matplotlib.figure.Figure
    """
    if poly is None and int(ds.attrs.get("shape_constrained", 0)):
        poly = minkowski_polyhedron(ds["facet_normal"].values, ds["facet_area"].values)
    curves = np.unique(ds["light_curve"].values)
    rows = int(np.ceil(curves.size / CURVES_PER_ROW))
    fig = new_figure(12.0, 7.0 + 2.0 * rows)
    grid = fig.add_gridspec(2 + rows, CURVES_PER_ROW, height_ratios=[1.3, 1.3] + [1.0] * rows)
    ax = fig.add_subplot(grid[0, :2])
    ax.plot(ds["period"].values, ds["chi2_period"].values, ".-", lw=0.6, ms=2, color="k")
    ax.axvline(
        ds.attrs["period_h"], color="tab:red", lw=0.8, label=f"P = {ds.attrs['period_h']:.6f} h"
    )
    ax.locator_params(axis="x", nbins=5)
    ax.ticklabel_format(axis="x", useOffset=True, style="plain")
    ax.set_xlabel("trial period [h]")
    ax.set_ylabel("chi-square")
    ax.legend(fontsize="small")
    ax = fig.add_subplot(grid[0, 2:])
    lam, bet = ds["lambda"].values, ds["beta"].values
    mesh = ax.pcolormesh(lam, bet, ds["chi2_pole"].values, shading="nearest", cmap="viridis_r")
    fig.colorbar(mesh, ax=ax, label="chi-square")
    ax.plot(
        ds.attrs["pole_lambda_deg"],
        ds.attrs["pole_beta_deg"],
        "*",
        ms=12,
        color="tab:red",
        label="best",
    )
    if "mirror_lambda_deg" in ds.attrs:
        ax.plot(
            ds.attrs["mirror_lambda_deg"],
            ds.attrs["mirror_beta_deg"],
            "*",
            ms=10,
            color="tab:orange",
            label="mirror (fits as well)",
        )
    ax.set_xlabel("pole ecliptic longitude [deg]")
    ax.set_ylabel("pole ecliptic latitude [deg]")
    ax.legend(fontsize="small")
    ax.set_title(str(ds.attrs.get("verdict", "")), fontsize="x-small")
    _shape_views(fig, grid, poly)
    ax_text = fig.add_subplot(grid[1, 3])
    ax_text.axis("off")
    ax_text.text(0, 0.5, _summary(ds), fontsize="small", va="center")
    t = ds["time_jd"].values
    for k, c in enumerate(curves):
        ax = fig.add_subplot(grid[2 + k // CURVES_PER_ROW, k % CURVES_PER_ROW])
        m = ds["light_curve"].values == c
        hours = (t[m] - t[m][0]) * 24.0
        ax.errorbar(
            hours,
            ds["brightness"].values[m],
            ds["brightness_sigma"].values[m],
            fmt=".",
            ms=2,
            lw=0.4,
            color="0.4",
        )
        ax.plot(hours, ds["brightness_fit"].values[m], "-", lw=0.8, color="tab:red")
        ax.set_title(f"curve {c}: JD {t[m][0]:.3f}", fontsize="x-small")
        ax.tick_params(labelsize="x-small")
        ax.set_xlabel("time since its first point [h]", fontsize="x-small")
        if k % CURVES_PER_ROW == 0:  # the measured and fitted brightness, in the data's unit
            unit = ds["brightness"].attrs.get("units", "")
            ax.set_ylabel(f"brightness [{unit}]" if unit else "brightness", fontsize="x-small")
    return fig


def _summary(ds: xr.Dataset) -> str:
    a = ds.attrs
    return (
        f"P = {a['period_h']:.6f} +- {a['period_std_h']:.2g} h\n"
        f"pole (lambda, beta) = ({a['pole_lambda_deg']:.1f}, {a['pole_beta_deg']:.1f}) deg\n"
        f"  +- {a['pole_std_deg']:.2g} deg\n"
        f"law {a['law']}, {ds.sizes['facet']} facets\n"
        f"{a['n_points']} points in {a['n_curves']} curves"
    )
