"""Measured BRDF tables: resampled to a function of the half-vector angles, with their support.

The samples (:mod:`speclight.target.brdf_samples`) are in-plane curves f(theta_o) at a few
incidence angles. An isotropic BRDF is extended from them to all geometries with the
bivariate approximation f(theta_h, theta_d) (Romeiro, Vasilyev & Zickler 2008, "Passive
reflectometry", ECCV, doi:10.1007/978-3-540-88693-8_63): theta_h is the angle between the
half vector and the normal (the distance from the specular peak), theta_d the angle between
the incident direction and the half vector. Each measured curve is a pair of lines in the
(theta_h, theta_d) plane, ``theta_d = theta_i + theta_h`` (toward the specular side) and
``theta_d = |theta_i - theta_h|``; at a given theta_h the table interpolates linearly in
theta_d between the curves, so that lobes of different incidences are blended at the same
distance from their peaks.

**Support.** The table holds only where it interpolates between samples:

* theta_d between the smallest and largest sampled theta_d at that theta_h (between the
  measured incidences; nothing is extrapolated);
* theta_h at least the table's angular step (the smallest step of theta_o between
  neighbouring samples, 1 deg in the shipped tables): the specular peak is narrower than
  the sampling there, and its measured value depends on the instrument's aperture; extended
  to all azimuths it reflects more light than arrives (the Starlink v1.5 chassis table,
  interpolated through its peak, has a directional albedo of 1.7 at 15 deg incidence).

Outside the support the material's *extension* holds: an analytic model fitted to the table
(``speclight brdf-fit``; :mod:`speclight.target.brdf_fit`) with a directional albedo of at
most 1. The weight of the support is interpolated bilinearly, so the table and the extension
meet without a step over one grid cell. The renders record the fraction of the flux that
came from the extension (``outside_support_fraction`` and a flag bit of the output).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.target.brdf_samples import (
    SHIPPED_BRDF,
    TableSamples,
    half_angles_deg,
    read_table_samples,
)

__all__ = [
    "DEFAULT_EXTENSION",
    "EXTENSIONS",
    "GRID_D_DEG",
    "GRID_H_DEG",
    "SHIPPED_BRDF",
    "MeasuredBRDF",
    "half_angles_deg",
    "load_brdf_table",
]

F64 = NDArray[np.float64]
GRID_H_DEG = np.linspace(0.0, 90.0, 361)
GRID_D_DEG = np.linspace(0.0, 90.0, 181)
#: The analytic models a table may be extended with (fitted to it on first use).
EXTENSIONS: tuple[str, ...] = ("microfacet", "phong", "abg", "binomial")
#: The extension of a table that names none: its directional albedo is at most 1 for every
#: coefficient value and it rises toward grazing angles as Fresnel reflection does (the
#: binomial and ABg forms fit the shipped tables more closely: docs/brdf-models.md).
DEFAULT_EXTENSION = "microfacet"


@dataclass(frozen=True, eq=False)
class MeasuredBRDF:
    """A table on a regular (theta_h, theta_d) grid [deg], its support and its extension.

    Attributes
    ----------
    values
        f [sr-1] at the grid nodes (outside the support: the nearest supported node's, so
        that :meth:`__call__` is continuous).
    support
        1 at the nodes inside the support, 0 outside.
    wavelength_nm
        The wavelength of the measurement (NaN: not stated).
    source
        The table's name or path.
    extension
        The analytic model that holds outside the support, and its coefficients.
    """

    values: F64
    support: F64
    wavelength_nm: float
    source: str
    extension: tuple[str, dict[str, Any]]

    def _bilinear(self, grid: F64, theta_h_deg: F64, theta_d_deg: F64) -> F64:
        h = np.clip(theta_h_deg, 0.0, 90.0) / (GRID_H_DEG[1] - GRID_H_DEG[0])
        d = np.clip(theta_d_deg, 0.0, 90.0) / (GRID_D_DEG[1] - GRID_D_DEG[0])
        i0 = np.minimum(h.astype(int), len(GRID_H_DEG) - 2)
        j0 = np.minimum(d.astype(int), len(GRID_D_DEG) - 2)
        fh, fd = h - i0, d - j0
        return np.asarray(
            (1 - fh) * (1 - fd) * grid[i0, j0]
            + fh * (1 - fd) * grid[i0 + 1, j0]
            + (1 - fh) * fd * grid[i0, j0 + 1]
            + fh * fd * grid[i0 + 1, j0 + 1]
        )

    def __call__(self, theta_h_deg: F64, theta_d_deg: F64) -> F64:
        """The table's f [sr-1] at half-vector angles [deg] (bilinear, broadcast)."""
        return self._bilinear(self.values, theta_h_deg, theta_d_deg)

    def inside(self, theta_h_deg: F64, theta_d_deg: F64) -> F64:
        """Weight of the support [0, 1] at half-vector angles [deg]: 1 inside, 0 outside."""
        return self._bilinear(self.support, theta_h_deg, theta_d_deg)

    def table_part(self, cos_h: F64, cos_d: F64) -> F64:
        """The table's part of f [sr-1] at the shading cosines: f times the support weight."""
        th = np.degrees(np.arccos(np.clip(cos_h, -1.0, 1.0)))
        td = np.degrees(np.arccos(np.clip(cos_d, -1.0, 1.0)))
        return self.inside(th, td) * self(th, td)

    def extension_part(self, cos_i: F64, cos_o: F64, cos_h: F64, cos_d: F64) -> F64:
        """The extension's part of f [sr-1]: the fitted model times one minus the support
        weight (0 inside the support). With :meth:`table_part`, the material's BRDF."""
        from speclight.target.brdf_fit.form_coefficients import evaluate

        th = np.degrees(np.arccos(np.clip(cos_h, -1.0, 1.0)))
        td = np.degrees(np.arccos(np.clip(cos_d, -1.0, 1.0)))
        out = 1.0 - self.inside(th, td)
        some = np.flatnonzero(out > 0)
        name, coefficients = self.extension
        ci, co, ch, cd = (np.asarray(c)[some] for c in (cos_i, cos_o, cos_h, cos_d))
        out[some] *= evaluate(name, coefficients, ci, co, ch, cd)
        return out


def angular_step_deg(samples: TableSamples) -> float:
    """The smallest step of theta_o between neighbouring samples of one curve [deg]."""
    steps: list[float] = []
    for ti in np.unique(samples.theta_i_deg):
        to = np.unique(samples.theta_o_deg[samples.theta_i_deg == ti])
        steps.extend(np.diff(to))
    positive = np.asarray(steps)[np.asarray(steps) > 1e-9]
    return float(positive.min()) if positive.size else 0.0


def _curve_points(
    samples: TableSamples, keep: NDArray[np.bool_]
) -> list[list[tuple[float, float]]]:
    """At each theta_h of the grid: the (theta_d, f) of every curve's two branches there."""
    points: list[list[tuple[float, float]]] = [[] for _ in GRID_H_DEG]
    ti_all, to_all, f_all = (
        a[keep] for a in (samples.theta_i_deg, samples.theta_o_deg, samples.brdf)
    )
    for ti in np.unique(ti_all):
        on = ti_all == ti
        to, f = to_all[on], f_all[on]
        for forward in (True, False):
            branch = to >= ti if forward else to <= ti
            th = np.abs(to[branch] - ti) / 2.0
            if th.size < 2:
                continue
            order = np.argsort(th)
            th, fb = th[order], f[branch][order]
            reach = (GRID_H_DEG >= th[0]) & (GRID_H_DEG <= th[-1])
            values = np.interp(GRID_H_DEG[reach], th, fb)
            td = ti + GRID_H_DEG[reach] if forward else np.abs(ti - GRID_H_DEG[reach])
            for j, d, v in zip(np.flatnonzero(reach), td, values, strict=True):
                points[j].append((float(d), float(v)))
    return points


def _grid(samples: TableSamples) -> tuple[F64, F64]:
    """(values, support) on the (theta_h, theta_d) grid (module doc)."""
    keep = samples.usable()
    values = np.full((len(GRID_H_DEG), len(GRID_D_DEG)), np.nan)
    for j, pts in enumerate(_curve_points(samples, keep)):
        if len(pts) < 2:
            continue
        p = np.array(sorted(pts))
        within = (GRID_D_DEG >= p[0, 0]) & (GRID_D_DEG <= p[-1, 0])
        values[j, within] = np.interp(GRID_D_DEG[within], p[:, 0], p[:, 1])
    support = np.isfinite(values) & (GRID_H_DEG[:, None] >= angular_step_deg(samples))
    if not support.any():
        raise InputError(
            f"the {int(keep.sum())} samples with incidence and exitance zenith below 90 deg do "
            "not span an area in (theta_h, theta_d): measure curves at two or more incidence "
            "angles, sampled more finely than their spread",
            source=samples.source,
        )
    from scipy.ndimage import distance_transform_edt

    # outside the support: the nearest supported node (continuity of __call__ only)
    _, (ih, idd) = distance_transform_edt(~support, return_indices=True)
    return values[ih, idd], support.astype(float)


@cache
def load_brdf_table(name_or_path: str, extension: str = DEFAULT_EXTENSION) -> MeasuredBRDF:
    """A shipped (by name) or user BRDF table with its support and ``extension`` (one of
    :data:`EXTENSIONS`, fitted to the table; see the module doc)."""
    from speclight.target.brdf_fit.directional_albedo import warn_if_creating_energy
    from speclight.target.brdf_fit.log_fit import fit_table_samples

    samples = read_table_samples(name_or_path)
    values, support = _grid(samples)
    try:
        fit = fit_table_samples(samples, extension)
    except InputError as exc:
        raise InputError(
            f"fitting the table's extension ({extension}), which holds outside its support: "
            f"{exc.message}",
            source=samples.source,
            field=exc.field,
        ) from None
    table = MeasuredBRDF(
        values, support, samples.wavelength_nm, samples.source, (extension, fit.coefficients)
    )
    warn_if_creating_energy(
        f"BRDF table {samples.source} (with its {extension} extension)",
        lambda *c: table.table_part(c[2], c[3]) + table.extension_part(*c),
        "its in-plane curves, extended to all azimuths, reflect more light than arrives; "
        "use an analytic model fitted to it (speclight brdf-fit) instead",
    )
    return table
