"""Tabulated target ephemeris in a CSV file.

Format::

    # frame: GCRS            (or ITRF; required, before the column header)
    # any other comment lines
    time_utc,x_km,y_km,z_km  (or x_m,y_m,z_m)
    2020-07-18T00:00:00Z,1169.919983,-6884.965286,-1783.893428
    ...

Times are ISO 8601 UTC (a trailing ``Z`` is allowed), strictly increasing; at least two
rows. Positions are interpolated with the 10-point Lagrange scheme shared with the CPF
reader (:mod:`speclight.orbit.interpolate`) in the file's frame; ITRF results are then
rotated to GCRS at each epoch.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError, did_you_mean
from speclight.input_files import read_user_text
from speclight.orbit.cpf import interpolate_table_m
from speclight.orbit.frames import EarthOrientation, TimeLike, earth_orientation

FRAMES = ("GCRS", "ITRF")
UNITS = {"m": 1.0, "km": 1000.0}
ACCEPTED_HEADERS = "time_utc,x_m,y_m,z_m  or  time_utc,x_km,y_km,z_km"


@dataclass(frozen=True)
class Ephemeris:
    """A tabulated ephemeris.

    Attributes
    ----------
    path
        File read.
    frame
        "GCRS" or "ITRF".
    times_utc
        (M,) epochs, ``datetime64[ns]`` UTC.
    r_m
        (M, 3) positions [m] in ``frame``.
    """

    path: str
    frame: Literal["GCRS", "ITRF"]
    times_utc: NDArray[np.datetime64]
    r_m: NDArray[np.float64]


def read_ephemeris_csv(path: str | Path) -> Ephemeris:
    """Read a tabulated ephemeris CSV file (see the module docstring for the format).

    Raises
    ------
    InputError
        Missing or unknown frame, unaccepted column headers or units, unreadable values,
        fewer than 2 rows, or times not strictly increasing.
    """
    p = str(path)
    frame: str | None = None
    rows: list[tuple[int, list[str]]] = []
    header: list[str] | None = None
    text = read_user_text(path, "orbit.ephemeris_file", what="ephemeris file")
    for lineno, line in enumerate(text.split("\n"), start=1):
        s = line.strip()
        if not s:
            continue
        if s.startswith("#"):
            key, _, value = s.lstrip("#").partition(":")
            if key.strip().lower() == "frame":
                frame = value.strip().upper()
                if frame not in FRAMES:
                    raise InputError(
                        f"line {lineno}: frame {value.strip()!r} is not accepted"
                        f"{did_you_mean(frame, FRAMES)} (choices: GCRS, ITRF)",
                        source=p,
                        field="frame",
                    )
            continue
        try:
            cells = [c.strip() for c in next(csv.reader([s]))]
        except csv.Error as exc:  # e.g. a field above the csv module's size limit
            raise InputError(f"line {lineno}: not a CSV row ({exc})", source=p) from None
        if header is None:
            header = [c.lower() for c in cells]
        else:
            rows.append((lineno, cells))
    if frame is None:
        raise InputError(
            "no frame given: add a comment line '# frame: GCRS' or '# frame: ITRF' before "
            "the column header",
            source=p,
            field="frame",
        )
    if header is None or len(header) != 4 or header[0] != "time_utc":
        raise InputError(
            f"column header {header} is not accepted; use {ACCEPTED_HEADERS}",
            source=p,
            field="header",
        )
    units = set()
    for name, axis in zip(header[1:], "xyz", strict=True):
        pre, _, unit = name.partition("_")
        if pre != axis or unit not in UNITS:
            raise InputError(
                f"column {name!r} is not accepted (axis {axis}, unit m or km); use "
                f"{ACCEPTED_HEADERS}",
                source=p,
                field=name,
            )
        units.add(unit)
    if len(units) != 1:
        raise InputError(
            f"columns mix units {sorted(units)}; use one unit: {ACCEPTED_HEADERS}",
            source=p,
            field="header",
        )
    scale = UNITS[units.pop()]
    if len(rows) < 2:
        raise InputError(f"{len(rows)} data rows; need at least 2", source=p)
    times = []
    pos = []
    for lineno, cells in rows:
        try:
            if len(cells) != 4:
                raise ValueError(f"{len(cells)} columns instead of 4")
            ts = cells[0][:-1] if cells[0].upper().endswith("Z") else cells[0]
            times.append(np.datetime64(ts, "ns"))
            pos.append([float(c) * scale for c in cells[1:]])
        except ValueError as exc:
            raise InputError(
                f"line {lineno}: cannot read {','.join(cells)!r} ({exc}); expected an ISO UTC "
                "time and three numbers",
                source=p,
            ) from exc
    t_arr = np.array(times, dtype="datetime64[ns]")
    bad = np.flatnonzero(np.diff(t_arr) <= np.timedelta64(0, "ns"))
    if bad.size:
        raise InputError(
            f"row {bad[0] + 2} ({t_arr[bad[0] + 1]}) is not after the previous row; times must "
            "increase strictly",
            source=p,
        )
    r = np.array(pos, dtype=np.float64)
    if not np.all(np.isfinite(r)):
        raise InputError("positions must be finite numbers", source=p)
    return Ephemeris(path=p, frame=frame, times_utc=t_arr, r_m=r)  # type: ignore[arg-type]


def ephemeris_position_gcrs_m(
    eph: Ephemeris, t: TimeLike, orientation: EarthOrientation | None = None
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Interpolated GCRS position [m] (N, 3) and ok mask (False outside the table's span)."""
    r, ok = interpolate_table_m(eph.times_utc, eph.r_m, t)
    if eph.frame == "GCRS":
        return r, ok
    eo = orientation if orientation is not None else earth_orientation(t)
    return eo.itrs_to_gcrs(r), ok
