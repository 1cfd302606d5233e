"""speclite's filter curves read from its data files, without importing ``speclite.filters``.

``speclite.filters`` imports ``astropy.table`` (about a second on a laptop) only to read its
ECSV files, which hold two plain columns (wavelength with a unit, response). Every simulation
needs one of them (``bessell-V`` for the Vega magnitude), so the files are read here with
numpy; tests check the result against ``speclite.filters.load_filter`` for every shipped filter.
"""

from __future__ import annotations

import importlib.util
import re
from functools import cache
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

#: Divisor from each ECSV wavelength unit speclite uses to nm (a division, so that Angstrom
#: values come out as speclite's Angstrom values / 10 did before, to the bit).
_UNITS_PER_NM = {"Angstrom": 10.0, "nm": 1.0, "micron": 1.0e-3, "um": 1.0e-3}

_COLUMN = re.compile(r"^#\s+-\s+\{name:\s*(?P<name>\w+)(?P<rest>[^}]*)\}")
_UNIT = re.compile(r"unit:\s*(?P<unit>\w+)")
_DATATYPE = re.compile(r"datatype:\s*(?P<dtype>\w+)")


def speclite_filter_folder() -> Path | None:
    """The folder of speclite's filter files, or None if speclite is not installed."""
    spec = importlib.util.find_spec("speclite")
    if spec is None or not spec.submodule_search_locations:
        return None
    return Path(next(iter(spec.submodule_search_locations))) / "data" / "filters"


@cache
def read_speclite_filter(path: Path) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """One speclite filter file: wavelength [nm] and response, trimmed as speclite does.

    Parameters
    ----------
    path
        A speclite ECSV filter file.

    Returns
    -------
    wavelength_nm, response
        The tabulated curve without the extra zeros speclite drops (one zero is kept on each
        side of the non-zero response, as ``speclite.filters.FilterResponse`` keeps it).

    Raises
    ------
    ValueError
        If the file does not hold a wavelength column with a known unit and a response column.
    """
    units: dict[str, str] = {}
    dtypes: dict[str, str] = {}
    names: list[str] = []
    rows: list[str] = []
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("#"):
            m = _COLUMN.match(line)
            if m is not None:
                unit = _UNIT.search(m["rest"])
                dtype = _DATATYPE.search(m["rest"])
                units[m["name"]] = unit["unit"] if unit else ""
                dtypes[m["name"]] = dtype["dtype"] if dtype else "float64"
        elif not names:
            names = line.split()
        elif line.strip():
            rows.append(line)
    if "wavelength" not in names or "response" not in names:
        raise ValueError(f"{path}: no wavelength and response columns (found {names})")
    if units.get("wavelength") not in _UNITS_PER_NM:
        raise ValueError(
            f"{path}: wavelength unit {units.get('wavelength')!r} is not one of "
            f"{', '.join(_UNITS_PER_NM)}"
        )
    table = np.array([r.split() for r in rows], dtype=np.float64)
    wavelength = table[:, names.index("wavelength")] / _UNITS_PER_NM[units["wavelength"]]
    response = table[:, names.index("response")]
    if dtypes.get("response") == "float32":  # read as astropy does, then widened
        response = response.astype(np.float32).astype(np.float64)
    non_zero = np.flatnonzero(response > 0)
    start, stop = max(int(non_zero[0]) - 1, 0), int(non_zero[-1]) + 2
    wavelength, response = wavelength[start:stop], response[start:stop]
    wavelength.setflags(write=False)  # shared by the cache
    response.setflags(write=False)
    return wavelength, response
