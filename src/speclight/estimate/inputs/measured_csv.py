"""The CSV of measured count rates (:func:`speclight.estimate.inputs.measured.read_measured`).

The first column is ``time`` (ISO 8601, UTC: ``2020-02-29T21:16:00Z``, a ``+00:00`` offset
or no offset), the others are count rates [s-1] named exactly as the scenario's bands,
optionally with ``<band>_sigma`` columns (the rates' standard deviations [s-1]); lines
starting with ``#`` are comments. Cells may be quoted (RFC 4180); spaces around a cell, a
UTF-8 byte-order mark and Windows line ends are ignored, and so are empty cells after the
last named column (the trailing commas a spreadsheet writes). Refused, naming the line and
the column: an empty or repeated column name, a ``_sigma`` column of no band, a row with
fewer cells than the header (a line cut short) or with a value in a column without a name,
unparseable numbers or times, a time with another UTC offset, a repeated time, and what
:mod:`.measured_checks` refuses. Rows out of time order are sorted, with a notice.
"""

from __future__ import annotations

import csv
import re
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.estimate.inputs.measured_checks import (
    check_epoch,
    check_order,
    check_rates,
    check_sigmas,
    check_signal,
)
from speclight.input_files import read_user_text

F64 = NDArray[np.float64]
FIELD = "MEASURED"
_OFFSET = re.compile(r"(Z|[+-]\d\d:?\d\d)$")


@dataclass(frozen=True)
class CsvLightCurve:
    """What a CSV of count rates holds: (N,) epochs (``datetime64[ns]``), (B,) band names,
    (N, B) rates [s-1] and their sigmas [s-1] (None without ``_sigma`` columns)."""

    time_utc: NDArray[np.datetime64]
    band_names: list[str]
    rate_per_s: F64
    sigma_per_s: F64 | None


def read_csv_columns(path: Path) -> CsvLightCurve:
    """The epochs, band names, rates and sigmas of a CSV (module docstring), checked."""
    src = str(path)
    text = read_user_text(path, FIELD, what="measurements")
    numbered = [
        (k, line)
        for k, line in enumerate(text.splitlines(), 1)
        if line.strip() and not line.lstrip().startswith("#")
    ]
    if not numbered:
        raise InputError("the file holds no header and no rows", source=src, field=FIELD)
    lines = [k for k, _ in numbered]
    rows = _csv_rows(numbered, src)
    header_line, columns = lines[0], _header(rows[0], lines[0], src)
    names = columns[1:]
    bands = [c for c in names if not c.endswith("_sigma")]
    for c in names:
        if c.endswith("_sigma") and c.removesuffix("_sigma") not in bands:
            raise InputError(
                f"line {header_line}: column '{c}' is the sigma of no band column "
                f"(bands: {', '.join(bands) or 'none'})",
                source=src,
                field=FIELD,
            )
    if not bands:
        raise InputError(
            f"line {header_line}: no band column; give 'time', then one column of count "
            "rates per band (and optionally '<band>_sigma')",
            source=src,
            field=FIELD,
        )
    if len(rows) < 2:
        raise InputError("the file holds a header but no rows", source=src, field=FIELD)
    times, values = [], []
    for k, cells in zip(lines[1:], rows[1:], strict=True):
        cells = _fit_row(cells, len(columns), k, src)
        times.append(parse_utc_time(cells[0], f"line {k}", src))
        values.append([_number(c, k, col, src) for c, col in zip(cells[1:], names, strict=True)])
    t = np.array(times, dtype="datetime64[ns]")
    order = np.argsort(t, kind="stable")
    line_of = [lines[1:][i] for i in order]
    if np.any(order != np.arange(t.size)):
        k = int(np.flatnonzero(np.diff(t) < np.timedelta64(0, "ns"))[0])
        warnings.warn(
            f"{src}: rows not in time order (line {lines[k + 2]} comes before line "
            f"{lines[k + 1]}); sorted by time",
            stacklevel=2,
        )
        t = t[order]
        values = [values[i] for i in order]

    def row(i: int) -> str:
        return f"line {line_of[i]}"

    def column(j: int) -> str:
        return f"column '{names[j]}'"

    check_order(t, row, src, FIELD)
    data = np.array(values, dtype=float).reshape(len(times), len(names))
    band_cols = [names.index(b) for b in bands]
    check_rates(data[:, band_cols], row, lambda j: column(band_cols[j]), src, FIELD)
    rate = data[:, band_cols]
    sigma = None
    if any(f"{b}_sigma" in names for b in bands):
        sigma = np.full(rate.shape, np.nan)
        for j, b in enumerate(bands):
            if f"{b}_sigma" in names:
                sigma[:, j] = data[:, names.index(f"{b}_sigma")]
        check_sigmas(
            sigma, rate, row, lambda j: column(names.index(f"{bands[j]}_sigma")), src, FIELD
        )
    check_signal(rate, bands, src, FIELD)
    return CsvLightCurve(t, bands, rate, sigma)


def _csv_rows(numbered: list[tuple[int, str]], src: str) -> list[list[str]]:
    """The cells of every line (RFC 4180: a cell may be quoted, but not span lines), each
    stripped of spaces."""
    rows = []
    for k, line in numbered:
        try:
            cells = next(csv.reader([line], skipinitialspace=True))
        except csv.Error as exc:
            raise InputError(f"line {k}: not a CSV row ({exc})", source=src, field=FIELD) from None
        rows.append([c.strip() for c in cells])
    return rows


def _header(cells: list[str], line: int, src: str) -> list[str]:
    """The header's column names: trailing empty cells (a spreadsheet's trailing commas)
    dropped; an empty or repeated name refused."""
    while cells and not cells[-1]:
        cells = cells[:-1]
    if not cells or cells[0] != "time":
        first = cells[0] if cells else ""
        raise InputError(
            f"line {line}: the first column must be 'time' (ISO 8601 UTC), got '{first}'",
            source=src,
            field=FIELD,
        )
    for j, name in enumerate(cells):
        if not name:
            raise InputError(
                f"line {line}, column {j + 1}: the header cell is empty; name every column: "
                "'time', then one per band (and optionally '<band>_sigma')",
                source=src,
                field=FIELD,
            )
        if name in cells[:j]:
            raise InputError(
                f"line {line}: column '{name}' is named twice (columns {cells.index(name) + 1} "
                f"and {j + 1}); give each band once",
                source=src,
                field=FIELD,
            )
    return cells


def _fit_row(cells: list[str], n: int, line: int, src: str) -> list[str]:
    """A row's ``n`` cells: empty cells after the last named column (trailing commas) are
    dropped; a row cut short, or a value in a column without a name, is refused."""
    if len(cells) > n and not any(cells[n:]):
        cells = cells[:n]
    if len(cells) < n:
        raise InputError(
            f"line {line}: {len(cells)} cells, the header names {n} (a line cut short?)",
            source=src,
            field=FIELD,
        )
    if len(cells) > n:
        extra = next(c for c in cells[n:] if c)
        raise InputError(
            f"line {line}: {len(cells)} cells, the header names {n}: '{extra}' is in a column "
            "without a name",
            source=src,
            field=FIELD,
        )
    return cells


def parse_utc_time(text: str, where: str, src: str, field: str = FIELD) -> np.datetime64:
    """An ISO 8601 UTC time (a ``Z`` or ``+00:00`` suffix, or none) as ``datetime64[ns]``,
    within the ephemeris span (:func:`.measured_checks.check_epoch`).

    ``where`` names the place in the file for messages (``"line 5"``).
    """
    m = _OFFSET.search(text)
    body = text
    if m:
        if m.group(1) not in ("Z", "+00:00", "+0000", "-00:00"):
            raise InputError(
                f"{where}: time '{text}' has the UTC offset {m.group(1)}; give UTC "
                "(a 'Z' or '+00:00' suffix, or none)",
                source=src,
                field=field,
            )
        body = text[: m.start()]
    try:
        t = np.datetime64(body)
    except ValueError:
        raise InputError(
            f"{where}: '{text}' is not an ISO 8601 time (e.g. 2020-02-29T21:16:00Z)",
            source=src,
            field=field,
        ) from None
    if np.isnat(t) or not body.strip():
        raise InputError(f"{where}: time '{text}' is not a time", source=src, field=field)
    return check_epoch(t, where, text, src, field)


def _number(text: str, line: int, column: str, src: str) -> float:
    if text == "" or text.lower() == "nan":
        return np.nan
    try:
        return float(text)
    except ValueError:
        raise InputError(
            f"line {line}: '{text}' in column '{column}' is not a number", source=src, field=FIELD
        ) from None
