"""Tabulated target ephemeris in a CSV file.

Format::

    # frame: GCRS            (or ITRF; required, before the column header)
    # any other comment lines
    time_utc,x_km,y_km,z_km  (or x_m,y_m,z_m)
    2020-07-18T00:00:00Z,1169.919983,-6884.965286,-1783.893428
    ...

Times are ISO 8601 UTC (a trailing ``Z`` is allowed), strictly increasing; at least two
rows. Positions are finite numbers whose geocentric distance is that of an Earth orbit
(:data:`~speclight.orbit.cpf.PLAUSIBLE_RADIUS_M`, 6,000 to 2 million km); a table in
metres under ``_km`` headers (or the other way round) is refused with that diagnosis.

Positions are interpolated with the 10-point Lagrange scheme shared with the CPF reader
(:mod:`speclight.orbit.interpolate`) in the file's frame; ITRF results are then rotated to
GCRS at each epoch. A hole in the table is not bridged: epochs between two rows more than
:data:`MAX_GAP_STEPS` times the table's median step apart are not valid (a table need not
be evenly spaced, so the threshold leaves room for uneven steps; the CPF reader uses 1.5
times the step its header announces).
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
from speclight.orbit.cpf import PLAUSIBLE_RADIUS_M, interpolate_table_m, plausible_position
from speclight.orbit.frames import EarthOrientation, TimeLike, earth_orientation

FRAMES = ("GCRS", "ITRF")
UNITS = {"m": 1.0, "km": 1000.0}
ACCEPTED_HEADERS = "time_utc,x_m,y_m,z_m  or  time_utc,x_km,y_km,z_km"
#: Epochs in a gap between rows longer than this many median table steps are not valid.
MAX_GAP_STEPS = 3.0
#: Span of ``datetime64[ns]``; numpy wraps times beyond it around silently.
_TIME_RANGE = (np.datetime64("1678-01-01T00:00:00", "s"), np.datetime64("2262-01-01T00:00:00", "s"))


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
        The file is missing or not UTF-8 text (see
        :func:`~speclight.input_files.read_user_text`), missing or unknown frame,
        unaccepted column headers or units, unreadable or non-finite values, positions
        that are no Earth orbit in the stated unit, fewer than 2 rows, or times not
        strictly increasing.
    """
    p = str(path)
    text = read_user_text(path, "orbit.ephemeris_file", what="ephemeris file")
    frame, header, rows = _lines(p, text)
    unit = _unit(p, header)
    if len(rows) < 2:
        raise InputError(f"{len(rows)} data rows; need at least 2", source=p)
    times, pos = _rows(p, rows)
    t_arr = np.array(times, dtype="datetime64[ns]")
    bad = np.flatnonzero(np.diff(t_arr) <= np.timedelta64(0, "ns"))
    if bad.size:
        raise InputError(
            f"row {bad[0] + 2} ({t_arr[bad[0] + 1]}) is not after the previous row; times must "
            "increase strictly",
            source=p,
        )
    r_m = _positions_m(p, unit, np.array(pos, dtype=np.float64), [ln for ln, _ in rows])
    return Ephemeris(path=p, frame=frame, times_utc=t_arr, r_m=r_m)  # type: ignore[arg-type]


def _lines(p: str, text: str) -> tuple[str, list[str], list[tuple[int, list[str]]]]:
    """The frame (its comment line), the column header and the data rows (line, cells)."""
    frame: str | None = None
    rows: list[tuple[int, list[str]]] = []
    header: list[str] | None = None
    for lineno, line in enumerate(text.split("\n"), start=1):
        s = line.strip()
        if not s:
            continue
        if s.startswith("#"):
            frame = _frame_comment(p, lineno, s) or frame
            continue
        try:
            cells = [c.strip() for c in next(csv.reader([s]))]
        except csv.Error as exc:  # e.g. a field above the csv module's size limit
            raise InputError(f"line {lineno}: not a CSV row ({exc})", source=p) from None
        if header is None:
            header = [c.lower() for c in cells]
        else:
            rows.append((lineno, cells))
    return _checked_head(p, frame, header), header or [], rows


def _checked_head(p: str, frame: str | None, header: list[str] | None) -> str:
    """The frame, after checking that the file gives one and an accepted column header."""
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
    return frame


def _frame_comment(p: str, lineno: int, s: str) -> str | None:
    """The frame a comment line ``# frame: GCRS`` names (None for another comment)."""
    key, _, value = s.lstrip("#").partition(":")
    if key.strip().lower() != "frame":
        return None
    frame = value.strip().upper()
    if frame not in FRAMES:
        raise InputError(
            f"line {lineno}: frame {value.strip()!r} is not accepted"
            f"{did_you_mean(frame, FRAMES)} (choices: GCRS, ITRF)",
            source=p,
            field="frame",
        )
    return frame


def _unit(p: str, header: list[str]) -> str:
    """The one unit (m or km) of the x, y, z columns of the header."""
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
    return units.pop()


def _rows(
    p: str, rows: list[tuple[int, list[str]]]
) -> tuple[list[np.datetime64], list[list[float]]]:
    """The times and positions (in the file's unit) of the data rows."""
    times = []
    pos = []
    for lineno, cells in rows:
        try:
            if len(cells) != 4:
                raise ValueError(f"{len(cells)} columns instead of 4")
            times.append(_utc(cells[0]))
            pos.append([float(c) for c in cells[1:]])
        except ValueError as exc:
            raise InputError(
                f"line {lineno}: cannot read {','.join(cells)!r} ({exc}); expected an ISO UTC "
                "time and three numbers",
                source=p,
            ) from exc
    return times, pos


def _utc(cell: str) -> np.datetime64:
    """A UTC time cell as ``datetime64[ns]``; ValueError if it is not a time of 1678-2262."""
    t = np.datetime64(cell[:-1] if cell.upper().endswith("Z") else cell)
    if np.isnat(t):
        raise ValueError("not a time")
    if not _TIME_RANGE[0] <= t < _TIME_RANGE[1]:
        raise ValueError("the time is outside 1678-2262")
    return t.astype("datetime64[ns]")


def _positions_m(
    path: str, unit: str, r_file: NDArray[np.float64], lines: list[int]
) -> NDArray[np.float64]:
    """Positions [m] from the file's values in ``unit``; InputError for non-finite values
    and for positions that are no Earth orbit (naming the metres/km mix-up if it is one)."""
    finite = np.all(np.isfinite(r_file), axis=1)
    if not finite.all():
        i = int(np.flatnonzero(~finite)[0])
        raise InputError(
            f"line {lines[i]}: position {r_file[i].tolist()} {unit} is not three finite numbers",
            source=path,
        )
    with np.errstate(over="ignore"):
        r_m = r_file * UNITS[unit]
    ok = plausible_position(r_m)
    if ok.all():
        return r_m
    lo_km, hi_km = (v / 1e3 for v in PLAUSIBLE_RADIUS_M)
    with np.errstate(over="ignore"):
        radius_km = np.linalg.norm(r_m, axis=1) / 1e3
    i = int(np.flatnonzero(~ok)[0])
    msg = (
        f"line {lines[i]}: position {r_file[i].tolist()} {unit} is "
        f"{radius_km[i]:,.6g} km from the geocentre; an Earth orbit is {lo_km:,.0f} to "
        f"{hi_km:,.0f} km"
    )
    other = "m" if unit == "km" else "km"
    with np.errstate(over="ignore"):
        mislabelled = plausible_position(r_file * UNITS[other]).all()
    if not mislabelled:
        raise InputError(msg, source=path)
    raise InputError(
        f"the positions look like {'metres' if other == 'm' else 'kilometres'} labelled "
        f"{unit} ({msg}; a factor of 1000 makes every row an Earth orbit); write the header "
        f"time_utc,x_{other},y_{other},z_{other} or convert the values",
        source=path,
        field="header",
    )


def ephemeris_position_gcrs_m(
    eph: Ephemeris, t: TimeLike, orientation: EarthOrientation | None = None
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Interpolated GCRS position of the target.

    Parameters
    ----------
    eph
        From :func:`read_ephemeris_csv`.
    t
        Epochs (N), skyfield ``Time`` or UTC ``datetime64``.
    orientation
        Precomputed Earth orientation for ``t`` (ITRF tables only).

    Returns
    -------
    r_gcrs_m : ndarray
        (N, 3) [m]; NaN rows outside the table's span and inside gaps longer than
        :data:`MAX_GAP_STEPS` times the table's median step.
    ok : ndarray of bool
        (N,) True where valid.
    """
    step_s = float(np.median(np.diff(eph.times_utc) / np.timedelta64(1, "s")))
    r, ok = interpolate_table_m(eph.times_utc, eph.r_m, t, max_gap_s=MAX_GAP_STEPS * step_s)
    if eph.frame == "GCRS":
        return r, ok
    eo = orientation if orientation is not None else earth_orientation(t)
    return eo.itrs_to_gcrs(r), ok
