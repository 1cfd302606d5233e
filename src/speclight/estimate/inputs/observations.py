"""Observed magnitudes in: the OBSERVATIONS CSV of ``speclight compare``.

Format (``#`` lines are comments, except ``# key: value`` lines naming the site)::

    # latitude_deg: 48.7822          (one site for the whole file; or per-row columns)
    # longitude_deg: 9.1967
    # altitude_m: 355
    time,magnitude,magnitude_sigma,band
    2020-02-29T21:16:00Z,7.91,0.05,V
    2020-02-29T21:16:10Z,8.02,0.05,sdss2010-r

Columns (any order, names exact):

* ``time``: ISO 8601 UTC (a ``Z`` or ``+00:00`` suffix, or none);
* ``magnitude`` [mag], ``magnitude_sigma`` [mag] (> 0; an empty cell: not given);
* ``band``: a band name of the scenario, or a speclite filter name (``bessell-V``,
  ``sdss2010-r``); magnitudes are **AB** magnitudes in that band (see docs/compare.md for
  Vega-based catalogues);
* the site, ``latitude_deg``, ``longitude_deg``, ``altitude_m`` (geodetic, WGS84), either
  as columns (every row) or once in ``# key: value`` header lines, not both;
* optionally where the target was seen: ``elevation_deg``, ``azimuth_deg`` (from north
  through east, geometric) and ``range_m`` or ``height_m`` (above the WGS84 ellipsoid),
  for a scenario with ``orbit: {observed: true}``.

Rows need not be sorted; several rows may share an epoch (several bands).
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError, did_you_mean
from speclight.estimate.inputs.measured_csv import parse_utc_time
from speclight.input_files import read_user_text

F64 = NDArray[np.float64]
FIELD = "OBSERVATIONS"
SITE_KEYS = ("latitude_deg", "longitude_deg", "altitude_m")
POSITION_KEYS = ("elevation_deg", "azimuth_deg", "range_m", "height_m")
REQUIRED = ("time", "magnitude", "magnitude_sigma", "band")
COLUMNS = REQUIRED + SITE_KEYS + POSITION_KEYS
#: Accepted values per numeric column: (low, high, what it is).
RANGES = {
    "magnitude": (-30.0, 40.0, "an AB magnitude"),
    "magnitude_sigma": (0.0, 10.0, "a standard deviation > 0 [mag]"),
    "latitude_deg": (-90.0, 90.0, "a geodetic latitude [deg]"),
    "longitude_deg": (-180.0, 360.0, "a longitude east of Greenwich [deg]"),
    "altitude_m": (-500.0, 9000.0, "a site height above the WGS84 ellipsoid [m]"),
    "elevation_deg": (-90.0, 90.0, "an elevation [deg]"),
    "azimuth_deg": (-360.0, 360.0, "an azimuth from north through east [deg]"),
    "range_m": (1.0, 1e10, "a range [m] (metres, not km)"),
    "height_m": (0.0, 1e10, "a height above the WGS84 ellipsoid [m] (metres, not km)"),
}


@dataclass(frozen=True)
class Observations:
    """Observed magnitudes, one entry per CSV row, in file order.

    Attributes
    ----------
    time_utc
        (N,) epochs, UTC ``datetime64[ns]``.
    magnitude, magnitude_sigma
        (N,) AB magnitude and its standard deviation [mag] (NaN: not given).
    band
        (N,) band or filter names as written.
    latitude_deg, longitude_deg, altitude_m
        (N,) the site of each row.
    elevation_deg, azimuth_deg, range_m, height_m
        (N,) where the target was seen (NaN: not given).
    line
        (N,) line number of each row in the file.
    source
        The file read.
    """

    time_utc: NDArray[np.datetime64]
    magnitude: F64
    magnitude_sigma: F64
    band: list[str]
    latitude_deg: F64
    longitude_deg: F64
    altitude_m: F64
    elevation_deg: F64
    azimuth_deg: F64
    range_m: F64
    height_m: F64
    line: NDArray[np.int64]
    source: str

    @property
    def has_positions(self) -> bool:
        """Whether every row gives where the target was seen."""
        return bool(
            np.all(np.isfinite(self.elevation_deg) & np.isfinite(self.azimuth_deg))
            and np.all(np.isfinite(self.range_m) | np.isfinite(self.height_m))
        )

    def site_groups(self) -> list[tuple[tuple[float, float, float], NDArray[np.intp]]]:
        """Rows grouped by site: ``[((lat, lon, alt), row indices), ...]`` in first-seen order."""
        keys = list(zip(self.latitude_deg, self.longitude_deg, self.altitude_m, strict=True))
        groups: dict[tuple[float, float, float], list[int]] = {}
        for i, k in enumerate(keys):
            groups.setdefault((float(k[0]), float(k[1]), float(k[2])), []).append(i)
        return [(k, np.array(v, dtype=np.intp)) for k, v in groups.items()]


def _error(message: str, src: str) -> InputError:
    return InputError(message, source=src, field=FIELD)


def _value(text: str, line: int, column: str, src: str, required: bool) -> float:
    """A number of a column, checked against :data:`RANGES`; NaN for an empty cell."""
    low, high, what = RANGES[column]
    if text == "" or text.lower() == "nan":
        if required:
            raise _error(f"line {line}, column '{column}': a value is required ({what})", src)
        return np.nan
    try:
        x = float(text)
    except ValueError:
        x = np.nan
    positive = column in ("magnitude_sigma", "range_m")
    if not (low <= x <= high) or (positive and x <= 0):
        raise _error(
            f"line {line}, column '{column}': '{text}' is not accepted; expected {what} "
            f"within {low:g}..{high:g}",
            src,
        )
    return x


def _header_site(comments: list[tuple[int, str]], src: str) -> dict[str, float]:
    site: dict[str, float] = {}
    for lineno, text in comments:
        key, sep, value = text.lstrip("#").partition(":")
        key = key.strip()
        if not sep or key not in SITE_KEYS:
            continue  # a plain comment
        site[key] = _value(value.strip(), lineno, key, src, required=True)
    return site


def read_observations(path: str | Path) -> Observations:
    """Read an OBSERVATIONS CSV (see the module docstring for the format).

    Raises
    ------
    InputError
        Naming the file, the line, the column, the value and what is accepted: unreadable
        file, missing or unknown columns, a site both in the header and in columns (or in
        neither), unparseable or out-of-range values, a row with a position given only in
        part.
    """
    src = str(path)
    text = read_user_text(path, FIELD, what="observations")
    comments: list[tuple[int, str]] = []
    rows: list[tuple[int, list[str]]] = []
    header: list[str] | None = None
    header_line = 0
    for lineno, raw in enumerate(text.splitlines(), start=1):
        s = raw.strip()
        if not s:
            continue
        if s.startswith("#"):
            comments.append((lineno, s))
            continue
        try:
            cells = [c.strip() for c in next(csv.reader([s]))]
        except csv.Error as exc:
            raise _error(f"line {lineno}: not a CSV row ({exc})", src) from None
        if header is None:
            header, header_line = cells, lineno
        else:
            rows.append((lineno, cells))
    if header is None:
        raise _error("the file holds no header and no rows", src)
    for name in header:
        if name not in COLUMNS:
            raise _error(
                f"line {header_line}: unknown column '{name}'{did_you_mean(name, COLUMNS)} "
                f"(accepted: {', '.join(COLUMNS)})",
                src,
            )
    if len(set(header)) != len(header):
        raise _error(f"line {header_line}: a column is named twice ({', '.join(header)})", src)
    missing = [c for c in REQUIRED if c not in header]
    if missing:
        raise _error(
            f"line {header_line}: missing column(s) {', '.join(missing)} (required: "
            f"{', '.join(REQUIRED)})",
            src,
        )
    site = _header_site(comments, src)
    in_columns = [k for k in SITE_KEYS if k in header]
    if site and in_columns:
        raise _error(
            f"the site is given both in '# key: value' lines ({', '.join(site)}) and in "
            f"columns ({', '.join(in_columns)}); give it in one place",
            src,
        )
    for k in ("latitude_deg", "longitude_deg"):
        if k not in site and k not in header:
            raise _error(
                f"no {k}: give the site as columns latitude_deg, longitude_deg, altitude_m "
                "or as header lines '# latitude_deg: 48.78' (and longitude_deg, altitude_m)",
                src,
            )
    if "range_m" in header and "height_m" in header:
        raise _error(f"line {header_line}: give range_m or height_m, not both", src)
    if not rows:
        raise _error("the file holds a header but no rows", src)
    return _rows(src, header, rows, site)


def _rows(
    src: str, header: list[str], rows: list[tuple[int, list[str]]], site: dict[str, float]
) -> Observations:
    col = {name: i for i, name in enumerate(header)}
    n = len(rows)
    num = {k: np.full(n, np.nan) for k in RANGES}
    times, bands, lines = [], [], []
    for i, (lineno, cells) in enumerate(rows):
        if len(cells) != len(header):
            raise _error(f"line {lineno}: {len(cells)} cells, the header names {len(header)}", src)
        where = f"line {lineno}, column 'time'"
        times.append(parse_utc_time(cells[col["time"]], where, src, FIELD))
        band = cells[col["band"]]
        if not band:
            raise _error(
                f"line {lineno}, column 'band': a band name of the scenario or a speclite "
                "filter name (e.g. bessell-V) is required",
                src,
            )
        bands.append(band)
        lines.append(lineno)
        for k in RANGES:
            if k in col:
                required = k in ("magnitude", "latitude_deg", "longitude_deg")
                num[k][i] = _value(cells[col[k]], lineno, k, src, required)
        given = [k for k in ("elevation_deg", "azimuth_deg") if np.isfinite(num[k][i])]
        given += [k for k in ("range_m", "height_m") if np.isfinite(num[k][i])]
        if given and len(given) != 3:
            raise _error(
                f"line {lineno}: the target's position needs elevation_deg, azimuth_deg and "
                f"range_m (or height_m); this row gives {', '.join(given)}",
                src,
            )
    for k in SITE_KEYS:
        if k in site:
            num[k][:] = site[k]
    num["altitude_m"] = np.nan_to_num(num["altitude_m"], nan=0.0)
    return Observations(
        time_utc=np.array(times, dtype="datetime64[ns]"),
        magnitude=num["magnitude"],
        magnitude_sigma=num["magnitude_sigma"],
        band=bands,
        latitude_deg=num["latitude_deg"],
        longitude_deg=num["longitude_deg"],
        altitude_m=num["altitude_m"],
        elevation_deg=num["elevation_deg"],
        azimuth_deg=num["azimuth_deg"],
        range_m=num["range_m"],
        height_m=num["height_m"],
        line=np.array(lines, dtype=np.int64),
        source=src,
    )
