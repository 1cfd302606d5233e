"""Two-line element sets: strict parsing and SGP4 positions in the GCRS.

The TLE layout (column positions, checksum) is the NORAD/Space-Track format described in
Vallado, Crawford, Hujsak & Kelso (2006), "Revisiting Spacetrack Report #3", AIAA
2006-6753, doi:10.2514/6.2006-6753, Appendix B. Propagation is SGP4 through ``sgp4`` (the
same paper's reference implementation) and runs fully offline.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from sgp4.api import Satrec, jday
from skyfield.timelib import Time

from speclight.errors import InputError
from speclight.input_files import read_user_text
from speclight.orbit.frames import EarthOrientation, TimeLike, as_time, earth_orientation

#: Column template of each line ('N' a digit, 'A' a letter/character, 'C' a classification).
TEMPLATE = {
    1: "1 NNNNNC NNNNNAAA NNNNN.NNNNNNNN +.NNNNNNNN +NNNNN-N +NNNNN-N N NNNNN",
    2: "2 NNNNN NNN.NNNN NNN.NNNN NNNNNNN NNN.NNNN NNN.NNNN NN.NNNNNNNNNNNNNN",
}
# 1-based columns that must hold a blank / a period.
_BLANKS = {1: (2, 9, 18, 33, 44, 53, 62, 64), 2: (2, 8, 17, 26, 34, 43, 52)}
_PERIODS = {1: (24,), 2: (12, 21, 38, 47, 55)}
_ALPHA5 = "ABCDEFGHJKLMNPQRSTUVWXYZ"  # Alpha-5 catalogue numbers skip I and O


@dataclass(frozen=True)
class Tle:
    """A checked two-line element set.

    Attributes
    ----------
    name
        Satellite name from the title line, or "" for a bare two-line set.
    line1, line2
        The element lines (69 characters each).
    norad_id
        NORAD catalogue number (Alpha-5 numbers decoded).
    epoch
        Element epoch, UTC, ``datetime64[ns]``.
    """

    name: str
    line1: str
    line2: str
    norad_id: int
    epoch: np.datetime64


def checksum(line: str) -> int:
    """Modulo-10 checksum of the first 68 columns: digits add their value, '-' adds 1."""
    return sum(int(c) if c.isdigit() else (1 if c == "-" else 0) for c in line[:68]) % 10


def _template_error(source: str, number: int, line: str, what: str) -> InputError:
    msg = (
        f"TLE line {number} is malformed: {what}.\n"
        "The TLE format is fixed-column; here is the template of line "
        f"{number} ('N' = digit) above the line given:\n"
        f"  {TEMPLATE[number]}\n  {line}\n"
        "Fix the line (copy it again from the source without re-wrapping or trimming)."
    )
    return InputError(msg, source=source, field=f"line{number}")


def _check_line(source: str, number: int, line: str) -> None:
    if len(line) != 69:
        raise _template_error(source, number, line, f"found {len(line)} characters, expected 69")
    if line[0] != str(number):
        what = f"column 1 is {line[0]!r}, expected line number '{number}'"
        raise _template_error(source, number, line, what)
    for col in _BLANKS[number]:
        if line[col - 1] != " ":
            what = f"column {col} is {line[col - 1]!r}, expected a blank"
            raise _template_error(source, number, line, what)
    for col in _PERIODS[number]:
        if line[col - 1] != ".":
            what = f"column {col} is {line[col - 1]!r}, expected '.'"
            raise _template_error(source, number, line, what)
    if not line[68].isdigit():
        what = f"checksum column 69 is {line[68]!r}, expected a digit"
        raise _template_error(source, number, line, what)
    expected = checksum(line)
    if int(line[68]) != expected:
        what = (
            f"checksum mismatch: column 69 holds {line[68]}, the digits of columns 1-68 "
            f"sum (mod 10, '-' counts 1) to {expected}; the line is corrupted or edited"
        )
        raise _template_error(source, number, line, what)


def _norad_number(field: str) -> int:
    field = field.strip()
    if field[:1].isalpha():  # Alpha-5: letter = 10..33, then four digits
        return (10 + _ALPHA5.index(field[0].upper())) * 10000 + int(field[1:])
    return int(field)


def _epoch(line1: str) -> np.datetime64:
    yy = int(line1[18:20])
    year = 1900 + yy if yy >= 57 else 2000 + yy
    day = float(line1[20:32])
    ns = round((day - 1.0) * 86400e9)
    return np.datetime64(f"{year}-01-01T00:00:00", "ns") + np.timedelta64(ns, "ns")


def parse_tle(text: str, source: str = "orbit.tle") -> Tle:
    """Parse and check a two- or three-line element set.

    Parameters
    ----------
    text
        Two element lines, optionally preceded by a name line ("0 NAME" or "NAME");
        blank lines and surrounding whitespace are ignored.
    source
        Where the text came from, for error messages (file name or scenario field).

    Returns
    -------
    Tle

    Raises
    ------
    InputError
        Wrong number of lines, a line off the column template, line numbers not 1/2,
        catalogue numbers that differ, or a failed checksum.
    """
    lines = [ln.strip() for ln in str(text).strip().splitlines() if ln.strip()]
    if len(lines) not in (2, 3):
        raise InputError(
            f"a TLE has 2 element lines, optionally after a name line; found {len(lines)} "
            "non-blank lines. Give exactly one element set (use read_tle_file for files "
            "holding several).",
            source=source,
        )
    name = ""
    if len(lines) == 3:
        name = lines[0][2:].strip() if lines[0].startswith("0 ") else lines[0]
    line1, line2 = lines[-2], lines[-1]
    _check_line(source, 1, line1)
    _check_line(source, 2, line2)
    if line1[2:7] != line2[2:7]:
        raise InputError(
            f"catalogue numbers differ: line 1 has {line1[2:7]!r}, line 2 has {line2[2:7]!r}; "
            "the two lines come from different element sets",
            source=source,
            field="line2",
        )
    try:
        norad_id = _norad_number(line1[2:7])
        epoch = _epoch(line1)
        Satrec.twoline2rv(line1, line2)
    except (ValueError, IndexError) as exc:
        raise InputError(
            f"TLE fields could not be read ({exc}).\n  {TEMPLATE[1]}\n  {line1}\n"
            f"  {TEMPLATE[2]}\n  {line2}",
            source=source,
        ) from exc
    return Tle(name=name, line1=line1, line2=line2, norad_id=norad_id, epoch=epoch)


def read_tles(path: str | Path) -> list[Tle]:
    """Read every element set of a TLE/3LE file (name lines optional).

    Raises
    ------
    InputError
        The file is missing, not a regular UTF-8 text file (see
        :func:`~speclight.input_files.read_user_text`), holds no element set, or one of
        its sets is malformed (the message names the line).
    """
    p = Path(path)
    text = read_user_text(p, "orbit.tle_file", what="TLE file")
    lines = [ln.strip() for ln in text.split("\n")]  # line numbers as in the file
    out: list[Tle] = []
    for i, ln in enumerate(lines):
        if re.match(r"^1 ", ln) and i + 1 < len(lines) and lines[i + 1].startswith("2 "):
            has_name = i > 0 and lines[i - 1] and not re.match(r"^[12] ", lines[i - 1])
            block = ([lines[i - 1]] if has_name else []) + [ln, lines[i + 1]]
            out.append(parse_tle("\n".join(block), source=f"{p}:{i + 1}"))
    if not out:
        raise InputError(
            "no element set found (expected lines starting '1 ' then '2 ')", source=str(p)
        )
    return out


def read_tle_file(
    path: str | Path, norad_id: int | None = None, near_epoch: np.datetime64 | None = None
) -> Tle:
    """Pick one element set from a file of many.

    Parameters
    ----------
    path
        TLE or 3LE text file.
    norad_id
        Catalogue number to select; may be omitted if the file holds one object.
    near_epoch
        If several sets match, the one whose epoch is closest to this UTC time; by
        default the latest.

    Returns
    -------
    Tle
    """
    tles = read_tles(path)
    ids = sorted({t.norad_id for t in tles})
    if norad_id is None:
        if len(ids) > 1:
            raise InputError(
                f"the file holds several objects (NORAD ids {ids}); choose one with norad_id",
                source=str(path),
                field="norad_id",
            )
        norad_id = ids[0]
    match = [t for t in tles if t.norad_id == int(norad_id)]
    if not match:
        raise InputError(
            f"NORAD id {norad_id} is not in the file; ids found: {ids}",
            source=str(path),
            field="norad_id",
        )
    if near_epoch is None:
        return max(match, key=lambda t: t.epoch)
    ref = np.asarray(near_epoch).astype("datetime64[ns]").astype(np.int64)
    return min(match, key=lambda t: abs(int(np.asarray(t.epoch).astype(np.int64) - ref)))


def utc_julian_date(t: Time) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """UTC Julian date of skyfield times as SGP4 takes it (AIAA 2006-6753): whole + fraction.

    From the public UTC calendar of the time (``Time.utc``, which applies the leap-second
    table of the timescale) and sgp4's ``jday``; the split keeps the fraction's precision.
    """
    year, month, day, hour, minute, second = t.utc
    jd, fr = jday(year, month, day, hour, minute, second)
    jd_a = np.atleast_1d(np.asarray(jd, dtype=np.float64))
    return jd_a, np.atleast_1d(np.asarray(fr, dtype=np.float64))


def tle_position_teme_m(
    tle: Tle, t: TimeLike
) -> tuple[NDArray[np.float64], NDArray[np.bool_], NDArray[np.int_]]:
    """SGP4 position in the TEME frame [m], the ok mask and sgp4's error codes (0 = ok)."""
    t = as_time(t)
    sat = Satrec.twoline2rv(tle.line1, tle.line2)
    jd, fr = utc_julian_date(t)
    err, r_km, _ = sat.sgp4_array(jd, fr)
    ok = (err == 0) & np.all(np.isfinite(r_km), axis=1)
    r_m = np.where(ok[:, None], r_km * 1e3, np.nan)
    return r_m, ok, err


def tle_position_gcrs_m(
    tle: Tle, t: TimeLike, orientation: EarthOrientation | None = None
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """SGP4 position of the target in the GCRS.

    Parameters
    ----------
    tle
        Element set from :func:`parse_tle`.
    t
        Epochs (N), skyfield ``Time`` or UTC ``datetime64``.
    orientation
        Precomputed :func:`~speclight.orbit.frames.earth_orientation` for ``t``.

    Returns
    -------
    r_gcrs_m : ndarray
        (N, 3) geocentric position [m]; NaN rows where SGP4 failed (decayed orbit,
        eccentricity out of range...: sgp4 error codes 1-6).
    ok : ndarray of bool
        (N,) True where the row is valid.
    """
    r_teme, ok, _ = tle_position_teme_m(tle, t)
    eo = orientation if orientation is not None else earth_orientation(t)
    return eo.teme_to_gcrs(r_teme), ok
