"""Measured BRDF tables, resampled to a function of the half-vector angles.

Format (as in Fankhauser, Askari & Tyson 2023, "Satellite optical brightness",
doi:10.48550/arXiv.2305.11123, repository Forrest-Fankhauser/satellite-optical-brightness):
``#`` comment lines, then rows ``phi_i theta_i phi_o theta_o brdf`` with phi the zenith and theta
the azimuth angle [deg] and the BRDF [sr-1]; a comment ``lambda = 532 nm`` gives the wavelength.
Shipped tables: ``starlink_v1p5_chassis_532nm``, ``starlink_v1p5_solar_array_532nm``.

An isotropic BRDF measured in the plane of incidence is extended to all geometries with the
bivariate approximation f(theta_h, theta_d) (Romeiro, Vasilyev & Zickler 2008, "Passive
reflectometry", ECCV, doi:10.1007/978-3-540-88693-8_63): theta_h is the angle between the
half vector and the normal, theta_d the angle between the incident direction and the half
vector. Samples are interpolated linearly in (theta_h, theta_d) onto a regular grid; outside
the measured range the nearest sample is used.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import cache
from importlib import resources
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError, did_you_mean
from speclight.input_files import read_user_text

SHIPPED_BRDF: tuple[str, ...] = ("starlink_v1p5_chassis_532nm", "starlink_v1p5_solar_array_532nm")
GRID_H_DEG = np.linspace(0.0, 90.0, 361)
GRID_D_DEG = np.linspace(0.0, 90.0, 91)


@dataclass(frozen=True, eq=False)
class MeasuredBRDF:
    """BRDF [sr-1] on a regular (theta_h, theta_d) grid [deg], measured at ``wavelength_nm``."""

    values: NDArray[np.float64]
    wavelength_nm: float
    source: str

    def __call__(
        self, theta_h_deg: NDArray[np.float64], theta_d_deg: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """Bilinear lookup of f [sr-1] at half-vector angles [deg] (broadcast)."""
        h = np.clip(theta_h_deg, 0.0, 90.0) / (GRID_H_DEG[1] - GRID_H_DEG[0])
        d = np.clip(theta_d_deg, 0.0, 90.0) / (GRID_D_DEG[1] - GRID_D_DEG[0])
        i0 = np.minimum(h.astype(int), len(GRID_H_DEG) - 2)
        j0 = np.minimum(d.astype(int), len(GRID_D_DEG) - 2)
        fh, fd = h - i0, d - j0
        v = self.values
        return (
            (1 - fh) * (1 - fd) * v[i0, j0]
            + fh * (1 - fd) * v[i0 + 1, j0]
            + (1 - fh) * fd * v[i0, j0 + 1]
            + fh * fd * v[i0 + 1, j0 + 1]
        )


def half_angles_deg(
    theta_i_deg: NDArray[np.float64], theta_o_signed_deg: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(theta_h, theta_d) [deg] of in-plane samples; theta_o > 0 on the specular side.

    Both are angles between vectors, so >= 0: beyond the retro-reflection direction
    (theta_o < -theta_i) the half vector passes the incident direction and theta_d is
    ``|theta_i + theta_o| / 2`` (a signed value would put those samples outside the grid).
    """
    return (
        np.abs(theta_o_signed_deg - theta_i_deg) / 2.0,
        np.abs(theta_i_deg + theta_o_signed_deg) / 2.0,
    )


def _parse_rows(text: str, source: str) -> NDArray[np.float64]:
    """The (n, 5) rows ``phi_i theta_i phi_o theta_o brdf`` of a table, checked."""
    rows: list[list[float]] = []
    for lineno, line in enumerate(text.splitlines(), start=1):
        tokens = line.split("#", 1)[0].split()
        if not tokens:
            continue
        try:
            row = [float(t) for t in tokens]
        except ValueError:
            row = []
        if len(row) != 5 or not np.all(np.isfinite(row)):
            raise InputError(
                f"line {lineno} {line.strip()[:60]!r} is not 5 finite numbers "
                "'phi_i theta_i phi_o theta_o brdf' (deg, sr-1)",
                source=source,
            )
        if row[4] < 0:
            raise InputError(f"line {lineno}: BRDF {row[4]:g} sr-1 must be >= 0", source=source)
        rows.append(row)
    if len(rows) < 3:
        raise InputError(
            f"BRDF table needs at least 3 rows 'phi_i theta_i phi_o theta_o brdf', found "
            f"{len(rows)}",
            source=source,
        )
    return np.asarray(rows, dtype=np.float64)


@cache
def load_brdf_table(name_or_path: str) -> MeasuredBRDF:
    """Read a shipped (by name) or user BRDF table (see the module doc for the format)."""
    if name_or_path in SHIPPED_BRDF:
        res = resources.files("speclight").joinpath("data", "brdf", f"{name_or_path}.csv")
        text, source = res.read_text(), name_or_path
    else:
        p = Path(name_or_path)
        if not p.exists():
            raise InputError(
                f"BRDF table '{name_or_path}' is neither a file nor a shipped table"
                f"{did_you_mean(name_or_path, SHIPPED_BRDF)} (shipped: {', '.join(SHIPPED_BRDF)})",
                field="brdf_table",
            )
        text, source = read_user_text(p, "brdf_table"), str(p)
    m = re.search(r"lambda\s*=\s*([0-9.]+)\s*nm", text)
    wavelength = float(m.group(1)) if m else float("nan")
    rows = _parse_rows(text, source)
    zen_i, az_i, zen_o, az_o, f = rows.T
    # In-plane samples: signed outgoing zenith, positive on the side opposite the source.
    same_plane = np.isclose(np.cos(np.radians(az_i - az_o)) ** 2, 1.0)
    if not np.all(same_plane):
        raise InputError(
            "only in-plane BRDF tables are supported (theta_o = theta_i +/- 180)", source=source
        )
    opposite = np.cos(np.radians(az_i - az_o)) < 0
    theta_o = np.where(opposite, zen_o, -zen_o)
    th, td = half_angles_deg(np.abs(zen_i), theta_o)
    keep = (np.abs(theta_o) < 90.0) & (np.abs(zen_i) < 90.0)
    from scipy.interpolate import LinearNDInterpolator, NearestNDInterpolator
    from scipy.spatial import QhullError

    pts = np.c_[th[keep], td[keep]]
    hh, dd = np.meshgrid(GRID_H_DEG, GRID_D_DEG, indexing="ij")
    try:
        lin = LinearNDInterpolator(pts, f[keep])(hh, dd)
    except (QhullError, ValueError):
        raise InputError(
            f"the {int(keep.sum())} samples with incidence and exitance zenith below 90 deg do "
            "not span an area in (theta_h, theta_d): measure at least 3 geometries that are "
            "not on one line",
            source=source,
        ) from None
    near = NearestNDInterpolator(pts, f[keep])(hh, dd)
    grid = np.where(np.isfinite(lin), lin, near)
    return MeasuredBRDF(grid, wavelength, source)
