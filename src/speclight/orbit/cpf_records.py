"""The records of an ILRS CPF file, read line by line (see :mod:`speclight.orbit.cpf`).

Records are read as blank-separated fields, as the ILRS/EDC validation does ("there must be
12 parameters in record H1"), which accepts both versions' column layouts: H1 (version,
source, target), H2 (ids, span, step, reference frame), H5 (centre-of-mass offset), H9, 10
(positions), 20 (velocities), 99 (end); H3, H4, H6-H8, 00, 30-70 are skipped.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from speclight.errors import InputError

MJD0 = np.datetime64("1858-11-17T00:00:00", "ns")
FRAME_NAMES = {
    0: "geocentric true body-fixed (ITRF)",
    1: "geocentric space-fixed, true of date",
    2: "geocentric space-fixed, mean of date J2000",
}
_SKIPPED = {"H3", "H4", "H6", "H7", "H8", "00", "30", "40", "50", "60", "70"}
#: Span of ``datetime64[ns]`` (beyond it numpy wraps around silently), as MJDs: 1678-2262.
_MJD_RANGE = (-66_000, 147_000)


def _err(path: str, lineno: int, line: str, what: str, fix: str) -> InputError:
    return InputError(f"line {lineno}: {what}\n  {line}\n{fix}", source=path)


def _datetime(fields: list[str]) -> np.datetime64:
    y, mo, d, h, mi, s = (int(f) for f in fields)
    if not 1678 < y < 2262:  # datetime64[ns] would wrap around silently
        raise ValueError(f"year {y} is outside 1678-2262")
    return np.datetime64(f"{y:04d}-{mo:02d}-{d:02d}T{h:02d}:{mi:02d}:{s:02d}", "ns")


def _record_time(
    lineno: int, line: str, path: str, mjd_field: str, sod_field: str
) -> np.datetime64:
    """UTC epoch of a record 10 from its MJD and seconds-of-day fields."""
    fix = "Expected: 10 direction MJD seconds-of-day leap-second x y z."
    mjd, sod = int(mjd_field), float(sod_field)
    if not _MJD_RANGE[0] < mjd < _MJD_RANGE[1]:
        raise _err(path, lineno, line, f"MJD {mjd_field} is not a day of 1678-2262", fix)
    if not 0.0 <= sod < 86401.0:  # 86400.x only during a leap second
        raise _err(path, lineno, line, f"seconds of day {sod_field} is outside 0-86400", fix)
    return MJD0 + np.timedelta64(mjd, "D") + np.timedelta64(round(sod * 1e9), "ns")


@dataclass
class Records:
    """What the records of a CPF file hold, as read (:func:`_read_records`)."""

    head: dict[str, list[str]] = field(default_factory=dict)
    times: list[np.datetime64] = field(default_factory=list)
    pos: list[list[float]] = field(default_factory=list)
    pos_lines: list[int] = field(default_factory=list)
    vel: list[list[float]] = field(default_factory=list)
    vel_times: list[np.datetime64] = field(default_factory=list)
    version: int = 0
    com: float | None = None


#: ``(path, line number, line, its fields, records so far)`` -> None, per record type.
_Reader = Callable[[str, int, str, list[str], Records], None]


def read_records(p: str, lines: list[str]) -> Records:
    """Every record up to 99 (end of file), each read by its type's reader; H1 and H2 must
    be there."""
    rec = Records()
    for lineno, raw in enumerate(lines, start=1):
        line = raw.rstrip()
        kind = line[:2].upper()
        if kind == "99":
            break
        if not line.strip():
            continue
        if kind in _SKIPPED:
            continue
        reader = _READERS.get(kind)
        if reader is None:
            raise _err(
                p, lineno, line, f"unknown record type {kind!r}",
                "CPF records are H1-H9, 00, 10, 20, 30, 40, 50, 60, 70, 99.",
            )  # fmt: skip
        try:
            reader(p, lineno, line, line.split(), rec)
        except InputError:
            raise
        except ValueError as exc:
            raise _err(
                p, lineno, line, f"record {kind} has an unreadable field ({exc})",
                "Check the record against the CPF format description.",
            ) from exc  # fmt: skip
    for name in ("H1", "H2"):
        if name not in rec.head:
            raise InputError(f"missing {name} header record; is this an ILRS CPF file?", source=p)
    return rec


def _h1(p: str, lineno: int, line: str, tok: list[str], rec: Records) -> None:
    """H1: format version, source, target name."""
    if len(tok) < 3 or tok[1].upper() != "CPF":
        raise _err(
            p, lineno, line, "H1 record does not start 'H1 CPF'", "This is not an ILRS CPF file."
        )
    rec.version = int(tok[2])
    if rec.version not in (1, 2):
        raise _err(
            p, lineno, line, f"format version {rec.version} is not supported",
            "Accepted: CPF format versions 1 and 2.",
        )  # fmt: skip
    need = 10 if rec.version == 1 else 11
    if len(tok) < need:
        raise _err(
            p, lineno, line, f"H1 has {len(tok)} fields, version {rec.version} needs {need}",
            "Expected: H1 CPF version source yyyy mm dd hh sequence "
            + ("" if rec.version == 1 else "sub-daily-sequence ")
            + "target",
        )  # fmt: skip
    rec.head["H1"] = tok


def _h2(p: str, lineno: int, line: str, tok: list[str], rec: Records) -> None:
    """H2: ids, span, step, reference frame (read by :func:`h2_span`)."""
    if len(tok) < 20:
        raise _err(
            p, lineno, line, f"H2 has {len(tok)} fields, need at least 20",
            "Expected: H2 cospar sic norad start(y m d h m s) end(y m d h m"
            " s) step tiv target-class reference-frame ...",
        )  # fmt: skip
    rec.head["H2"] = tok


def _h5(p: str, lineno: int, line: str, tok: list[str], rec: Records) -> None:
    """H5: centre-of-mass offset."""
    rec.head["H5"] = tok
    rec.com = float(tok[1]) if len(tok) > 1 else None


def _h9(p: str, lineno: int, line: str, tok: list[str], rec: Records) -> None:
    """H9: end of header."""
    rec.head["H9"] = tok


def _position(p: str, lineno: int, line: str, tok: list[str], rec: Records) -> None:
    """10: a position (common-epoch records only; direction flags 1, 2 are skipped)."""
    if len(tok) != 8:
        raise _err(
            p, lineno, line, f"position record has {len(tok)} fields, need 8",
            "Expected: 10 direction MJD seconds-of-day leap-second x y z.",
        )  # fmt: skip
    if int(tok[1]) != 0:
        return
    rec.times.append(_record_time(lineno, line, p, tok[2], tok[3]))
    rec.pos.append([float(v) for v in tok[5:8]])
    rec.pos_lines.append(lineno)


def _velocity(p: str, lineno: int, line: str, tok: list[str], rec: Records) -> None:
    """20: the velocity at the last position's epoch."""
    if len(tok) != 5:
        raise _err(
            p, lineno, line, f"velocity record has {len(tok)} fields, need 5",
            "Expected: 20 direction vx vy vz.",
        )  # fmt: skip
    if int(tok[1]) != 0:
        return
    rec.vel.append([float(v) for v in tok[2:5]])
    rec.vel_times.append(rec.times[-1] if rec.times else MJD0)


_READERS: dict[str, _Reader] = {
    "H1": _h1,
    "H2": _h2,
    "H5": _h5,
    "H9": _h9,
    "10": _position,
    "20": _velocity,
}


def h2_span(
    p: str, lines: list[str], h2: list[str]
) -> tuple[np.datetime64, np.datetime64, int, int]:
    """Start, end, step [s] and reference frame of the H2 record (frame 0 only)."""
    lineno = next(i for i, ln in enumerate(lines, 1) if ln[:2].upper() == "H2")
    try:
        start, end = _datetime(h2[4:10]), _datetime(h2[10:16])
        step_s, frame = int(h2[16]), int(h2[19])
    except ValueError as exc:
        raise _err(
            p, lineno, lines[lineno - 1], f"H2 has an unreadable field ({exc})",
            "Expected integers for the dates, step and reference frame.",
        ) from exc  # fmt: skip
    if frame != 0:
        raise _err(
            p, lineno, lines[lineno - 1],
            f"reference frame {frame} ({FRAME_NAMES.get(frame, 'unknown')}) is not supported",
            "Only frame 0 (geocentric true body-fixed, ITRF), the ILRS default for "
            "Earth satellites, is read; obtain the frame-0 prediction.",
        )  # fmt: skip
    return start, end, step_s, frame
