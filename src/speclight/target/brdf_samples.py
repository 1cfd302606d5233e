"""The samples of a measured in-plane BRDF table, read and checked.

Format (as in Fankhauser, Askari & Tyson 2023, "Satellite optical brightness",
doi:10.48550/arXiv.2305.11123, repository Forrest-Fankhauser/satellite-optical-brightness):
``#`` comment lines, then rows ``phi_i theta_i phi_o theta_o brdf`` with phi the zenith and theta
the azimuth angle [deg] and the BRDF [sr-1]; a comment ``lambda = 532 nm`` gives the wavelength.
A first line that is the column header itself (``phi_i theta_i phi_o theta_o brdf``, not
commented, as in the second-generation Starlink tables of Kandula et al. 2025) is skipped.
Shipped tables: ``starlink_v1p5_chassis_532nm``, ``starlink_v1p5_solar_array_532nm``.
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

F64 = NDArray[np.float64]
SHIPPED_BRDF: tuple[str, ...] = ("starlink_v1p5_chassis_532nm", "starlink_v1p5_solar_array_532nm")
_HEADER = ["phi_i", "theta_i", "phi_o", "theta_o", "brdf"]


@dataclass(frozen=True, eq=False)
class TableSamples:
    """The in-plane samples of a table: incidence and signed exitance zenith [deg], BRDF.

    Attributes
    ----------
    theta_i_deg
        Incidence zenith angle [deg], >= 0.
    theta_o_deg
        Exitance zenith angle [deg], positive on the side opposite the source (the
        specular side), negative toward it.
    brdf
        The measured BRDF [sr-1].
    wavelength_nm
        The wavelength of the measurement (NaN: not stated).
    source
        The table's name or path, for messages.
    """

    theta_i_deg: F64
    theta_o_deg: F64
    brdf: F64
    wavelength_nm: float
    source: str

    def cosines(self) -> tuple[F64, F64, F64, F64]:
        """(cos_i, cos_o, cos_h, cos_d) of every sample (surface normal +z)."""
        ti, to = np.radians(self.theta_i_deg), np.radians(self.theta_o_deg)
        i = np.stack([-np.sin(ti), np.zeros_like(ti), np.cos(ti)], axis=1)
        o = np.stack([np.sin(to), np.zeros_like(to), np.cos(to)], axis=1)
        h = i + o
        h = h / np.maximum(np.linalg.norm(h, axis=1), 1e-300)[:, None]
        cos_d = np.clip(np.einsum("pk,pk->p", i, h), 0.0, 1.0)
        return i[:, 2], o[:, 2], np.clip(h[:, 2], -1.0, 1.0), cos_d

    def usable(self) -> NDArray[np.bool_]:
        """Samples inside the hemisphere (zenith angles below 90 deg)."""
        return (np.abs(self.theta_o_deg) < 90.0) & (self.theta_i_deg < 90.0)


def half_angles_deg(theta_i_deg: F64, theta_o_signed_deg: F64) -> tuple[F64, F64]:
    """(theta_h, theta_d) [deg] of in-plane samples; theta_o > 0 on the specular side.

    Both are angles between vectors, so >= 0: beyond the retro-reflection direction
    (theta_o < -theta_i) the half vector passes the incident direction and theta_d is
    ``|theta_i + theta_o| / 2`` (a signed value would put those samples outside the grid).
    """
    return (
        np.abs(theta_o_signed_deg - theta_i_deg) / 2.0,
        np.abs(theta_i_deg + theta_o_signed_deg) / 2.0,
    )


def _parse_rows(text: str, source: str) -> F64:
    """The (n, 5) rows ``phi_i theta_i phi_o theta_o brdf`` of a table, checked."""
    rows: list[list[float]] = []
    for lineno, line in enumerate(text.splitlines(), start=1):
        tokens = line.split("#", 1)[0].split()
        if not tokens or (not rows and tokens == _HEADER):
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


def _table_text(name_or_path: str) -> tuple[str, str]:
    """The text of a shipped (by name) or user table, and its name for messages."""
    if name_or_path in SHIPPED_BRDF:
        res = resources.files("speclight").joinpath("data", "brdf", f"{name_or_path}.csv")
        return res.read_text(), name_or_path
    p = Path(name_or_path)
    if not p.exists():
        raise InputError(
            f"BRDF table '{name_or_path}' is neither a file nor a shipped table"
            f"{did_you_mean(name_or_path, SHIPPED_BRDF)} (shipped: {', '.join(SHIPPED_BRDF)})",
            field="brdf_table",
        )
    return read_user_text(p, "brdf_table"), str(p)


@cache
def read_table_samples(name_or_path: str) -> TableSamples:
    """The checked in-plane samples of a shipped (by name) or user table (module doc)."""
    text, source = _table_text(name_or_path)
    m = re.search(r"lambda\s*=\s*([0-9.]+)\s*nm", text)
    wavelength = float(m.group(1)) if m else float("nan")
    zen_i, az_i, zen_o, az_o, f = _parse_rows(text, source).T
    # In-plane samples: signed outgoing zenith, positive on the side opposite the source.
    same_plane = np.isclose(np.cos(np.radians(az_i - az_o)) ** 2, 1.0)
    if not np.all(same_plane):
        raise InputError(
            "only in-plane BRDF tables are supported (theta_o = theta_i +/- 180)", source=source
        )
    opposite = np.cos(np.radians(az_i - az_o)) < 0
    theta_o = np.where(opposite, zen_o, -zen_o)
    # a negative incidence zenith is the same geometry seen from the other side
    theta_o = np.where(zen_i < 0, -theta_o, theta_o)
    return TableSamples(np.abs(zen_i), theta_o, f, wavelength, source)
