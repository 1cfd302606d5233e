"""User-supplied transmission tables: wavelength x airmass.

File format (CSV; ``#`` starts a comment line; commas, semicolons, tabs or spaces)::

    # direct-beam transmission of my site, 1 = clear
    wavelength_nm, 1.0, 1.5, 2.0, 3.0
    400, 0.700, 0.586, 0.490, 0.343
    405, 0.712, 0.601, 0.507, 0.361
    ...

The header is required: the first column names the wavelength and its unit
(``wavelength_nm`` or ``wavelength_um``; unnamed wavelengths below 30 are read as
micrometres with a warning, see :mod:`speclight.instrument.tables`), the other columns
are airmasses (numbers >= 1, optionally written ``airmass=1.5`` or ``m1.5``). Values are
transmissions (fractions 0..1; percent is detected and converted with a warning). The
table must cover the wavelength grid. Between airmass columns, ``ln T`` is interpolated
linearly; beyond them it is extrapolated with the end segment (Beer-Lambert), and a single
column is scaled as ``T(m) = T(m0) ** (m / m0)`` (see :mod:`speclight.atmosphere.mapping`).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from speclight.atmosphere.airmass_pressure import airmass
from speclight.atmosphere.mapping import interpolate_in_airmass, log_transmission
from speclight.errors import InputError
from speclight.instrument.tables import read_table, sort_unique, value_to_fraction, wavelength_to_nm
from speclight.wavelength_grid import bin_average

FIELD = "atmosphere.table_file"
_NUMBER = re.compile(r"[-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?")


def read_transmission_table(
    path: str | Path,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Read a transmission table; return wavelength [nm] (n,), airmasses (K,), T (K, n)."""
    src = str(path)
    header, data = read_table(path, FIELD)
    if header is None:
        raise InputError(
            "the table needs a header line 'wavelength_nm, <airmass 1>, <airmass 2>, ...' "
            "naming the airmass of each transmission column",
            source=src,
            field=FIELD,
        )
    masses = []
    for name in header[1:]:
        found = _NUMBER.search(name)
        m = float(found.group()) if found else np.nan
        if not (m >= 1.0):
            raise InputError(
                f"column header {name!r} must be an airmass >= 1 (e.g. '1.0' or 'airmass=1.5')",
                source=src,
                field=FIELD,
            )
        masses.append(m)
    nodes = np.asarray(masses)
    if np.unique(nodes).size != nodes.size:
        raise InputError(f"airmass columns {header[1:]} repeat a value", source=src, field=FIELD)
    wl = wavelength_to_nm(data[:, 0], header[0], src, FIELD)
    order = np.argsort(nodes)
    t_all = value_to_fraction(data[:, 1:], None, src, FIELD)[:, order]
    cols = [sort_unique(wl, t_all[:, k]) for k in range(nodes.size)]
    return cols[0][0], nodes[order], np.asarray([c[1] for c in cols])


def table_transmission(
    wavelength_nm: NDArray[np.float64], elevation_deg: NDArray[np.float64], path: str | Path
) -> NDArray[np.float64]:
    """Transmission (N, L) from a user table, bin-averaged in wavelength, mapped in airmass.

    Raises
    ------
    InputError
        If the table does not cover the wavelength grid or is malformed.
    """
    wl_t, nodes, t = read_transmission_table(path)
    if wavelength_nm[0] < wl_t[0] or wavelength_nm[-1] > wl_t[-1]:
        raise InputError(
            f"the table covers {wl_t[0]:g}..{wl_t[-1]:g} nm but the wavelength grid spans "
            f"{wavelength_nm[0]:g}..{wavelength_nm[-1]:g} nm; extend the table or narrow "
            "spectrum.min_nm/max_nm",
            source=str(path),
            field=FIELD,
        )
    log_t = log_transmission(bin_average(wl_t, t, wavelength_nm, outside="edge"))
    return interpolate_in_airmass(nodes, log_t, airmass(elevation_deg))
