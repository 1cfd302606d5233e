"""IGS SP3 precise orbit files, versions c and d.

Format: S. Hilla, *The Extended Standard Product 3 Orbit Format (SP3-c)* (NGS, 2010) and
*(SP3-d)* (IGS, 2016). Read here: line 1 (``#c`` or ``#d``, position/velocity flag, start
epoch, number of epochs, coordinate system in columns 47-51, agency), line 2 (``##``: the
epoch interval in columns 25-38), the ``+`` satellite-list lines, the first ``%c`` line (time
system in columns 10-12: GPS, GAL, QZS, BDT, TAI, UTC, GLO; ``ccc`` as in SP3-a/b files
means GPS), ``/*`` comments, then per epoch a ``*`` line (year month day hour minute
second) and for each satellite a ``P`` line (vehicle id in columns 2-4, x y z in km in
columns 5-18, 19-32, 33-46, then the clock, which is ignored) and, in velocity files, a
``V`` line (dm/s; read for validation, not used). ``EP``/``EV`` lines are skipped; ``EOF``
ends the file. A position of 0.000000 (the format's "bad or absent") or 999999.999999 in a
coordinate is skipped.

Frames: the coordinate system named in the header (IGS14, IGb14, IGS20, ITRF...) is treated
as the ITRS (the realisations differ by centimetres) and rotated to the GCRS at each epoch.

Interpolation: 10-point (degree 9) Lagrange of the positions, the usual choice for SP3
precise orbits sampled every 15 or 5 minutes (Schenewerk, *A brief review of basic GPS orbit
interpolation strategies*, GPS Solutions 6, 265-267, 2003; Horemuz & Andersson, *Polynomial
interpolation of GPS satellite coordinates*, GPS Solutions 10, 67-72, 2006: millimetres for
GPS at 15 min with degree 8-10); ``tests/orbit/test_orbit_sp3.py`` measures it. A hole of
more than 1.5 epoch intervals (e.g. a skipped bad record) ends a segment: epochs in it, and
outside the file, are orbit failures, never extrapolated.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from speclight.errors import InputError, did_you_mean
from speclight.input_files import read_user_text
from speclight.orbit.frames import EarthOrientation, TimeLike
from speclight.orbit.state_table import Segment, as_ns, segments_position_gcrs_m, tai_julian

FIELD = "orbit.sp3_file"
#: SP3 time-system codes -> the scale of :func:`~speclight.orbit.state_table.tai_julian`
#: (Galileo, QZSS and IRNSS system times are steered to GPS time: TAI - 19 s).
TIME_SYSTEMS = {
    "GPS": "GPS",
    "GAL": "GPS",
    "QZS": "GPS",
    "IRN": "GPS",
    "BDT": "BDT",
    "TAI": "TAI",
    "UTC": "UTC",
    "GLO": "GLO",
    "CCC": "GPS",
}
BAD_VALUE = 999999.999999
N_POINTS = 10
MAX_GAP_STEPS = 1.5


@dataclass(frozen=True)
class Sp3:
    """One satellite's positions from an SP3 file.

    Attributes
    ----------
    path, version, satellite, coordinate_system, time_system
        As read (``version``: ``"c"`` or ``"d"``).
    interval_s
        Epoch interval from line 2 [s].
    segments
        Interpolable runs of good records.
    skipped_lines
        Lines of this satellite's bad records (0.000000 or 999999.999999).
    """

    path: str
    version: str
    satellite: str
    coordinate_system: str
    time_system: str
    interval_s: float
    segments: list[Segment]
    skipped_lines: list[int]


def normalise_id(text: str) -> str:
    """``"G1"``, ``"G 1"``, ``" 1"`` (SP3-a GPS) -> ``"G01"``."""
    s = text.strip().upper()
    letter = s[0] if s and s[0].isalpha() else "G"
    digits = (s[1:] if s and s[0].isalpha() else s).replace(" ", "0")
    return f"{letter}{digits.zfill(2)}" if digits.isdigit() else s


def _err(p: str, lineno: int, line: str, what: str) -> InputError:
    return InputError(f"line {lineno}: {what}: {line.rstrip()[:80]!r}", source=p)


def read_sp3(path: str | Path, satellite: str | None = None) -> Sp3:
    """Read the positions of one satellite from an SP3-c or SP3-d file.

    Parameters
    ----------
    path
        The file.
    satellite
        Vehicle id (``"G01"``; ``"G1"`` is accepted); may be left out when the file holds
        one satellite.

    Raises
    ------
    InputError
        Not an SP3-c/d file, unknown time system, a malformed line (named by its number),
        an unknown satellite (with a did-you-mean), or fewer than 2 good records.
    """
    p = str(path)
    lines = read_user_text(path, FIELD, what="SP3 file").splitlines()
    version, coord, interval_s = _header(p, lines)
    body = _Body()
    for lineno, line in enumerate(lines[2:], start=3):
        if line.strip() == "EOF":
            break
        reader = _reader(line, body)
        if reader is not None:
            reader(p, lineno, line, body)
    sat = _choose(p, satellite, body.listed or sorted(body.records), body.records)
    code = "GPS" if body.code == "CCC" else body.code
    return _table(p, version, sat, coord, code, interval_s, body.records.get(sat, []))


def _header(p: str, lines: list[str]) -> tuple[str, str, float]:
    """Version (``c``, ``d``), coordinate system and epoch interval [s] of lines 1-2."""
    if not lines or not lines[0].startswith(("#c", "#d")):
        head = lines[0][:3] if lines else "an empty file"
        raise InputError(
            f"line 1 starts {head!r}: not an SP3-c or SP3-d file (which start '#c' or '#d')",
            source=p,
        )
    try:
        interval_s = float(lines[1][24:38]) if lines[1].startswith("##") else math.nan
    except (IndexError, ValueError):
        interval_s = math.nan
    if not interval_s > 0:
        raise _err(p, 2, lines[1] if len(lines) > 1 else "", "no epoch interval in columns 25-38")
    return lines[0][1], lines[0][46:51].strip(), interval_s


@dataclass
class _Body:
    """What the lines after the header hold, as read."""

    listed: list[str] = field(default_factory=list)
    code: str = "GPS"
    seen_c: bool = False
    epoch: np.datetime64 | None = None
    records: dict[str, list[tuple[np.datetime64, int, list[float]]]] = field(default_factory=dict)


_LineReader = Callable[[str, int, str, _Body], None]


def _reader(line: str, body: _Body) -> _LineReader | None:
    """The reader of a body line (None: a line that is skipped)."""
    if line[:2] == "+ ":
        return _satellites
    if line[:2] == "%c" and not body.seen_c:
        return _time_system
    if line.startswith("* "):
        return _epoch
    if line.startswith("P"):
        return _position
    if line.startswith("V") and line[1:2].strip():
        return _velocity
    return None


def _satellites(p: str, lineno: int, line: str, body: _Body) -> None:
    """A ``+`` line: satellite ids in columns 10-60 ("  0" pads the list)."""
    ids = (line[i : i + 3] for i in range(9, min(len(line), 60), 3))
    body.listed += [normalise_id(x) for x in ids if x.strip(" 0")]


def _time_system(p: str, lineno: int, line: str, body: _Body) -> None:
    """The first ``%c`` line: the time system in columns 10-12."""
    body.seen_c = True
    body.code = line[9:12].strip().upper()
    if body.code not in TIME_SYSTEMS:
        raise _err(
            p,
            lineno,
            line,
            f"time system {body.code!r} is not known (accepted: "
            f"{', '.join(k for k in TIME_SYSTEMS if k != 'CCC')})",
        )


def _epoch(p: str, lineno: int, line: str, body: _Body) -> None:
    """A ``*`` line: the epoch of the position lines that follow."""
    try:
        y, mo, d, h, mi = (int(v) for v in line[1:].split()[:5])
        sec = float(line[1:].split()[5])
        day = as_ns(np.datetime64(f"{y:04d}-{mo:02d}-{d:02d}T{h:02d}:{mi:02d}"))
        body.epoch = day + np.timedelta64(round(sec * 1e9), "ns")
    except (ValueError, IndexError):
        raise _err(p, lineno, line, "not an epoch line '*  YYYY MM DD hh mm ss.ssss'") from None


def _position(p: str, lineno: int, line: str, body: _Body) -> None:
    """A ``P`` line: a satellite's x y z [km] at the current epoch."""
    if body.epoch is None:
        raise _err(p, lineno, line, "a position line before the first epoch line")
    try:
        xyz = [float(line[a:b]) for a, b in ((4, 18), (18, 32), (32, 46))]
    except ValueError:
        raise _err(p, lineno, line, "x y z [km] not in columns 5-18, 19-32, 33-46") from None
    body.records.setdefault(normalise_id(line[1:4]), []).append((body.epoch, lineno, xyz))


def _velocity(p: str, lineno: int, line: str, body: _Body) -> None:
    """A ``V`` line: read for validation only."""
    try:
        [float(line[a:b]) for a, b in ((4, 18), (18, 32), (32, 46))]
    except ValueError:
        raise _err(p, lineno, line, "vx vy vz [dm/s] not in columns 5-18, 19-32, 33-46") from None


def _choose(p: str, satellite: str | None, names: list[str], records: dict) -> str:
    if satellite is None:
        if len(names) == 1:
            return names[0]
        raise InputError(
            f"the file holds {len(names)} satellites ({', '.join(names[:12])}"
            f"{', ...' if len(names) > 12 else ''}); choose one with orbit.satellite",
            source=p,
            field="orbit.satellite",
        )
    sat = normalise_id(satellite)
    if sat not in records:
        known = sorted(records)
        more = ", ..." if len(known) > 12 else ""
        raise InputError(
            f"satellite {satellite!r} is not in the file{did_you_mean(sat, known)} "
            f"(satellites: {', '.join(known[:12])}{more})",
            source=p,
            field="orbit.satellite",
        )
    return sat


def _usable(xyz: list[float]) -> bool:
    """A position that is not the format's "bad or absent" (0.000000, 999999.999999)."""
    return any(v != 0.0 for v in xyz) and all(abs(v) != BAD_VALUE for v in xyz)


def _epochs(p: str, good: list) -> tuple[np.ndarray, np.ndarray]:
    """The records' epochs, checked to increase, and the steps between them [s]."""
    times = np.array([r[0] for r in good], dtype="datetime64[ns]")
    step = np.diff(times) / np.timedelta64(1, "s")
    if np.any(step <= 0):
        i = int(np.flatnonzero(step <= 0)[0]) + 1
        raise InputError(
            f"line {good[i][1]}: epoch {times[i]} is not after the previous one", source=p
        )
    return times, step


def _table(
    p: str, version: str, sat: str, coord: str, code: str, interval_s: float, recs: list
) -> Sp3:
    good = [r for r in recs if _usable(r[2])]
    skipped = [r[1] for r in recs if not _usable(r[2])]
    if len(good) < 2:
        raise InputError(
            f"satellite {sat}: {len(good)} good position records of {len(recs)}; need at least 2",
            source=p,
        )
    times, step = _epochs(p, good)
    r_m = np.array([r[2] for r in good], dtype=np.float64) * 1e3
    whole, frac = tai_julian(times, TIME_SYSTEMS[code])
    cuts = [0, *(np.flatnonzero(step > MAX_GAP_STEPS * interval_s) + 1).tolist(), len(good)]
    segments = [
        _segment(whole[a:b], frac[a:b], r_m[a:b])
        for a, b in itertools.pairwise(cuts)
        if b - a >= 2  # a lone record between holes is not interpolable
    ]
    return Sp3(p, version, sat, coord, code, interval_s, segments, skipped)


def _segment(whole: np.ndarray, frac: np.ndarray, r_m: np.ndarray) -> Segment:
    """An interpolable run of records (TAI Julian date parts, ITRS positions [m])."""
    w0 = float(whole[0])
    return Segment(
        frame="itrs",
        tai_whole=whole,
        tai_fraction=frac,
        r_m=r_m,
        v_m_s=None,
        method="lagrange",
        n_points=N_POINTS,
        valid_tai=(w0, float(frac[0]), float(whole[-1] - w0 + frac[-1])),
    )


def sp3_position_gcrs_m(
    sp3: Sp3, t: TimeLike, orientation: EarthOrientation | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """GCRS position [m] (N, 3) of the satellite at ``t`` and the ok mask (False, NaN rows,
    outside the file and in holes)."""
    return segments_position_gcrs_m(sp3.segments, t, orientation)
