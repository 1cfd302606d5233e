"""Photometric bands: Gaussian ``G-<centre>/<sigma>``, speclite filters, user tables.

Each band's response is put on the wavelength grid as its exact average over each bin
(a Gaussian through the error function, tables through their piecewise-linear
interpolant), so the band's integral is kept whatever the grid step.
"""

from __future__ import annotations

import difflib
import os
import re
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.special import ndtr

from speclight.errors import InputError, did_you_mean
from speclight.instrument.speclite_files import read_speclite_filter, speclite_filter_folder
from speclight.instrument.tables import read_table, sort_unique, value_to_fraction, wavelength_to_nm
from speclight.wavelength_grid import bin_average, bin_edges_nm, check_wavelength_grid

#: A band must have at least this fraction of its integrated response on the grid.
MIN_FRACTION_ON_GRID = 0.9

_GAUSS = re.compile(r"^G-(?P<c>\d+(?:\.\d*)?)/(?P<s>\d+(?:\.\d*)?)$")


@dataclass(frozen=True)
class Band:
    """One photometric band.

    Attributes
    ----------
    name
        Label in outputs, e.g. ``G-531/26``, ``bessell-V``, or a table's file stem.
    kind
        ``gaussian``, ``filter`` (speclite) or ``table``.
    center_nm, sigma_nm
        Gaussian centre and standard deviation [nm] (peak response 1).
    filter_name
        speclite filter name, e.g. ``sdss2010-r``.
    file
        Table path (wavelength, response).
    """

    name: str
    kind: Literal["gaussian", "filter", "table"]
    center_nm: float | None = None
    sigma_nm: float | None = None
    filter_name: str | None = None
    file: Path | None = None


#: Largest Gaussian band centre and sigma [nm]: 100 um, a hundred times any optical grid (a
#: wider band is flat across the grid; near 1e308 its normalisation overflows to NaN).
MAX_GAUSSIAN_NM = 1.0e5


def gaussian_band(center_nm: float, sigma_nm: float, name: str | None = None) -> Band:
    """A Gaussian band of peak 1; the default name is ``G-<centre>/<sigma>``."""
    c, s = float(center_nm), float(sigma_nm)
    if not (0 < c <= MAX_GAUSSIAN_NM and 0 < s <= MAX_GAUSSIAN_NM):  # False for NaN
        raise InputError(
            f"Gaussian band centre {center_nm!r} nm and sigma {sigma_nm!r} nm must be > 0 "
            f"and at most {MAX_GAUSSIAN_NM:g} nm",
            field="instrument.bands",
        )
    return Band(name or f"G-{c:g}/{s:g}", "gaussian", center_nm=c, sigma_nm=s)


def _require_speclite(reason: str) -> None:
    """An :class:`InputError` saying how to install speclite, if it is missing."""
    from speclight.engine_packages import require_engine

    require_engine("speclite", "instrument.bands", reason)


@cache
def speclite_filter_names() -> tuple[str, ...]:
    """All filter names shipped with speclite (``<group>-<band>``).

    Raises
    ------
    InputError
        If speclite is not installed (the message says how to install it).
    """
    _require_speclite("a speclite filter band")
    folder = speclite_filter_folder()
    assert folder is not None  # speclite is installed (checked above)
    return tuple(sorted(p.stem for p in folder.glob("*.ecsv")))


def filter_band(filter_name: str, name: str | None = None) -> Band:
    """A speclite filter band, checked against speclite's names (case-insensitive)."""
    _require_speclite(f"the filter band {filter_name!r}")
    names = speclite_filter_names()
    exact = {n.lower(): n for n in names}
    key = filter_name.strip()
    if key not in names:
        if key.lower() not in exact:
            near = difflib.get_close_matches(key, names, n=6, cutoff=0.5)
            near += [n for n in names if key.lower() in n.lower() and n not in near][:6]
            groups = sorted({n.rsplit("-", 1)[0] for n in names})
            raise InputError(
                f"unknown filter {filter_name!r}{did_you_mean(key, names)}; near matches: "
                f"{', '.join(near) if near else 'none'} (speclite groups: {', '.join(groups)};"
                " names are <group>-<band>, e.g. bessell-V, sdss2010-r)",
                field="instrument.bands",
            )
        key = exact[key.lower()]
    return Band(name or key, "filter", filter_name=key)


def table_band(path: str | os.PathLike, name: str | None = None) -> Band:
    """A band from a CSV table (wavelength, response); the default name is the file stem."""
    p = Path(path)
    return Band(name or p.stem, "table", file=p)


def parse_band(spec: str | Band) -> Band:
    """Band from its text form: ``G-531/26`` (a Gaussian of centre 531 nm and standard
    deviation, not FWHM, 26 nm), a speclite name, or a table file path."""
    if isinstance(spec, Band):
        return spec
    text = str(spec).strip()
    if text.upper().startswith("G-"):
        m = _GAUSS.match("G-" + text[2:])
        if m is None:
            raise InputError(
                f"Gaussian band {text!r} must read G-<centre_nm>/<sigma_nm> (sigma: the "
                "standard deviation, not the FWHM), e.g. G-531/26",
                field="instrument.bands",
            )
        return gaussian_band(float(m["c"]), float(m["s"]), name=text)
    if os.sep in text or "/" in text or Path(text).suffix.lower() in (".csv", ".txt", ".dat"):
        return table_band(text)
    return filter_band(text)


def _native(band: Band) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The band's own sampling: wavelength [nm], response."""
    if band.kind == "filter":
        _require_speclite(f"the speclite filter band {band.name!r}")
        folder = speclite_filter_folder()
        assert folder is not None and band.filter_name is not None
        return read_speclite_filter(folder / f"{band.filter_name}.ecsv")
    assert band.file is not None
    src = str(band.file)
    header, data = read_table(band.file, "instrument.bands")
    names: list[str | None] = list(header) if header else [None, None]
    x = wavelength_to_nm(data[:, 0], names[0], src, "instrument.bands")
    y = value_to_fraction(data[:, 1], names[1], src, "instrument.bands")
    return sort_unique(x, y)


def _one_response(band: Band, wl: NDArray[np.float64]) -> NDArray[np.float64]:
    edges = bin_edges_nm(wl)
    if band.kind == "gaussian":
        assert band.center_nm is not None and band.sigma_nm is not None
        c, s = band.center_nm, band.sigma_nm
        total = s * np.sqrt(2.0 * np.pi)
        response = np.diff(ndtr((edges - c) / s)) * total / np.diff(edges)
        lo, hi = c - 3 * s, c + 3 * s
    else:
        x, y = _native(band)
        trapz = 0.5 * (y[1:] + y[:-1]) * np.diff(x)
        total = float(trapz.sum())
        if total <= 0:
            raise InputError(f"band {band.name!r} has no response", field="instrument.bands")
        response = bin_average(x, y, wl, outside="zero")
        inside = y > 0.01 * y.max()
        lo, hi = float(x[inside][0]), float(x[inside][-1])
    on_grid = float(np.sum(response * np.diff(edges))) / total
    if on_grid < MIN_FRACTION_ON_GRID:
        raise InputError(
            f"band {band.name!r} ({lo:.0f}..{hi:.0f} nm) lies outside the wavelength grid "
            f"{wl[0]:g}..{wl[-1]:g} nm (only {100 * on_grid:.0f} % of its response is on it, "
            f"{100 * MIN_FRACTION_ON_GRID:.0f} % needed); extend spectrum.min_nm/max_nm or "
            "drop the band",
            field="instrument.bands",
        )
    return response


def band_response(bands: Sequence[str | Band], wavelength_nm: ArrayLike) -> NDArray[np.float64]:
    """Response of every band on the wavelength grid, bin-averaged.

    Parameters
    ----------
    bands
        Band specs: :class:`Band` objects or text (``G-<centre>/<sigma>``, a speclite
        filter name such as ``bessell-V`` or ``sdss2010-r``, or a table file path).
    wavelength_nm
        Grid (L,) [nm].

    Returns
    -------
    numpy.ndarray
        Response (B, L) [1] (peak 1 for Gaussians; as tabulated otherwise).

    Raises
    ------
    InputError
        Unknown filter (with near matches), malformed Gaussian name, bad table, or a band
        with less than :data:`MIN_FRACTION_ON_GRID` of its response on the grid.
    """
    wl = check_wavelength_grid(wavelength_nm)
    parsed = [parse_band(b) for b in bands]
    if not parsed:
        return np.zeros((0, wl.size))
    return np.stack([_one_response(b, wl) for b in parsed])
