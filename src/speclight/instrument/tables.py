"""Reading user tables of spectral curves: CSV parsing and unit detection.

Format: a text file with two or more columns separated by commas, semicolons, tabs or
spaces; lines starting with ``#`` are comments; an optional header line names the columns.
The first column is the wavelength, the others values.

Units are taken from the header when it names them (``wavelength_nm``, ``wavelength_um``,
``qe_percent``, ``transmission_fraction``, ``%``...). When it does not, they are inferred:
wavelengths below 30 are micrometres (no optical table in nm has all its wavelengths below
30 nm, and none in micrometres reaches 30 um), values above 1.5 are percent (a fraction
cannot exceed 1). An inference is announced with a :class:`UserWarning` saying what was
assumed; a header that contradicts its values is an error. Every value must be a finite
number: a NaN or inf in a table is an error that names the line, not NaN count rates later.

Files are read with :func:`speclight.input_files.read_user_text`, which makes a bad path (a
missing file, a folder, a FIFO, a device) or bytes that are not UTF-8 text a clear error.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.input_files import read_user_text

#: Wavelengths whose maximum is below this are read as micrometres when the header is silent.
UM_THRESHOLD = 30.0
#: Values whose maximum exceeds this are read as percent when the header is silent.
PERCENT_THRESHOLD = 1.5

_SPLIT = re.compile(r"[,;\t ]+")


def read_table(path: str | Path, field: str) -> tuple[list[str] | None, NDArray[np.float64]]:
    """Read a numeric table; return the header names (or None) and the data (n, k).

    Raises
    ------
    InputError
        If the file cannot be read as text (see :func:`read_user_text`), a row is not
        numeric or holds a NaN or inf, the column counts differ or there are fewer than 2
        rows or 2 columns.
    """
    p = Path(path).expanduser()
    header: list[str] | None = None
    rows: list[list[float]] = []
    for lineno, raw in enumerate(read_user_text(p, field).splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        parts = [c.strip().strip('"') for c in _SPLIT.split(line) if c.strip()]
        try:
            values = [float(c) for c in parts]
        except ValueError:
            if header is None and not rows:
                header = parts
                continue
            raise InputError(
                f"line {lineno} {line!r} is not numeric; expected columns like "
                "'wavelength_nm,value'",
                source=str(p),
                field=field,
            ) from None
        _check_row(f"line {lineno}", line, parts, values, rows, str(p), field)
        rows.append(values)
    return _checked_data(header, rows, str(p), field)


def _check_row(
    where: str,
    line: str,
    parts: list[str],
    values: list[float],
    rows: list[list[float]],
    source: str,
    field: str,
) -> None:
    """A numeric row: finite numbers, as many columns as the rows before it."""
    bad = [c for c, v in zip(parts, values, strict=True) if not np.isfinite(v)]
    if bad:
        raise InputError(
            f"{where} {line!r} holds {bad[0]!r}, which is not a finite number; a "
            "table needs a number in every column (cut the rows that have no value)",
            source=source,
            field=field,
        )
    if rows and len(values) != len(rows[0]):
        raise InputError(
            f"{where} has {len(values)} columns, earlier lines {len(rows[0])}",
            source=source,
            field=field,
        )


def _checked_data(
    header: list[str] | None, rows: list[list[float]], source: str, field: str
) -> tuple[list[str] | None, NDArray[np.float64]]:
    """The rows as an array of at least 2 rows and 2 columns; the header if it fits them."""
    data = np.asarray(rows, dtype=np.float64)
    if data.ndim != 2 or data.shape[0] < 2 or data.shape[1] < 2:
        found = f"{len(rows)} row(s) of {len(rows[0])} column(s)" if rows else "no numeric row"
        raise InputError(
            f"a table needs at least 2 rows of 'wavelength, value' columns; found {found}",
            source=source,
            field=field,
        )
    if header is not None and len(header) != data.shape[1]:
        header = None
    return header, data


def _check_finite(values: NDArray[np.float64], what: str, source: str, field: str) -> None:
    bad = ~np.isfinite(values)
    if np.any(bad):
        raise InputError(
            f"{what} hold {int(bad.sum())} value(s) that are not finite numbers "
            f"(first: {float(values[bad].flat[0])!r}); give a finite number for every wavelength",
            source=source,
            field=field,
        )


def _unit_in(name: str, tokens: tuple[str, ...]) -> bool:
    words = re.split(r"[^a-z%µ]+", name.lower())
    return any(t in words for t in tokens)


def wavelength_to_nm(
    values: NDArray[np.float64], name: str | None, source: str, field: str
) -> NDArray[np.float64]:
    """Convert a wavelength column to nm, from its header name or its magnitude."""
    says_um = name is not None and _unit_in(name, ("um", "µm", "micron", "microns", "micrometre"))
    says_nm = name is not None and _unit_in(name, ("nm", "nanometre", "nanometer"))
    top = _checked_wavelengths(values, name, (says_nm, says_um), source, field)
    if says_um:
        return values * 1000.0
    if says_nm:
        return values
    if top < UM_THRESHOLD:
        warnings.warn(
            f"{source}: wavelengths {np.nanmin(values):g}..{top:g} have no unit in the "
            f"header and are all below {UM_THRESHOLD:g}, so they are read as micrometres "
            "(x1000 to nm); name the column 'wavelength_nm' or 'wavelength_um' to say so",
            UserWarning,
            stacklevel=3,
        )
        return values * 1000.0
    return values


def _checked_wavelengths(
    values: NDArray[np.float64],
    name: str | None,
    says: tuple[bool, bool],
    source: str,
    field: str,
) -> float:
    """The largest wavelength, after checking that they are finite, > 0 and do not
    contradict the unit the header ``says`` (nm, um)."""
    says_nm, says_um = says
    _check_finite(values, "the wavelengths", source, field)
    if values.size == 0 or np.any(values <= 0):
        low = f"{values.min():g}" if values.size else "none"
        raise InputError(f"wavelengths must be > 0, got {low}", source=source, field=field)
    top = float(np.nanmax(values))
    if says_nm and top < UM_THRESHOLD:
        raise InputError(
            f"the wavelength column {name!r} says nm but its values "
            f"{np.nanmin(values):g}..{top:g} look like micrometres; rename the column to "
            "'wavelength_um' or multiply the wavelengths by 1000",
            source=source,
            field=field,
        )
    if says_um and top >= UM_THRESHOLD:
        raise InputError(
            f"the wavelength column {name!r} says micrometres but its values "
            f"{np.nanmin(values):g}..{top:g} look like nm; rename the column to "
            "'wavelength_nm' or divide the wavelengths by 1000",
            source=source,
            field=field,
        )
    return top


def value_to_fraction(
    values: NDArray[np.float64], name: str | None, source: str, field: str
) -> NDArray[np.float64]:
    """Convert a value column (efficiency, transmission) to a fraction 0..1."""
    says_pct, says_frac = _fraction_unit(name)
    _check_finite(values, "the values", source, field)
    top = float(np.nanmax(values))
    if says_frac and top > PERCENT_THRESHOLD:
        raise InputError(
            f"the column {name!r} says fraction but reaches {top:g}; if these are percent, "
            "rename it with '_percent' or divide by 100",
            source=source,
            field=field,
        )
    if says_pct:
        out = values / 100.0
    elif says_frac:
        out = values
    elif top > PERCENT_THRESHOLD:
        warnings.warn(
            f"{source}: values reach {top:g} and the header gives no unit, so they are read "
            "as percent (/100); name the column '..._percent' or '..._fraction' to say so",
            UserWarning,
            stacklevel=3,
        )
        out = values / 100.0
    else:
        out = values
    _check_fraction(out, source, field)
    return out


def _fraction_unit(name: str | None) -> tuple[bool, bool]:
    """Whether a column's header says percent, and whether it says fraction."""
    if name is None:
        return False, False
    says_pct = "%" in name or _unit_in(name, ("percent", "pct", "percentage"))
    return says_pct, _unit_in(name, ("fraction", "frac"))


def _check_fraction(out: NDArray[np.float64], source: str, field: str) -> None:
    """Fractions lie in 0..1 (to rounding)."""
    if np.any(out < 0) or np.any(out > 1.0 + 1e-6):
        raise InputError(
            f"values {np.nanmin(out):g}..{np.nanmax(out):g} (as a fraction) must lie in 0..1",
            source=source,
            field=field,
        )


def sort_unique(x: NDArray[np.float64], y: NDArray[np.float64]) -> tuple[NDArray, NDArray]:
    """Sort by wavelength and average rows that share a wavelength (digitised curves)."""
    order = np.argsort(x, kind="stable")
    xs, ys = x[order], y[order]
    ux, inverse = np.unique(xs, return_inverse=True)
    if ux.size == xs.size:
        return xs, ys
    sums = np.zeros(ux.size)
    np.add.at(sums, inverse, ys)
    return ux, sums / np.bincount(inverse)
