"""DAMIT's ``.lc`` light-curve files: reader and writer.

The exchange format of light-curve inversion (Durech et al. 2010, A&A 513, A46, the DAMIT
database; the input of Kaasalainen's ``convexinv``): the first line holds the number of
light curves; each light curve starts with a line ``N flag`` (``flag`` 0: relative
photometry, only the shape of the curve counts; 1: calibrated) followed by ``N`` lines

``JD brightness sun_x sun_y sun_z earth_x earth_y earth_z``

with the epoch as a Julian date (light-time corrected), the brightness in intensity units
(not magnitudes), and the vectors from the target to the Sun and to the observer in
ecliptic J2000 coordinates [AU]. Blank lines are ignored.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.input_files import read_user_text

F64 = NDArray[np.float64]
FIELD = "LC"


@dataclass(frozen=True)
class DamitLightCurve:
    """One light curve of a ``.lc`` file.

    Attributes
    ----------
    time_jd
        (N,) light-time corrected epochs, Julian date [d].
    brightness
        (N,) brightness [intensity units, relative or calibrated].
    sun_ecliptic_au
        (N, 3) target-to-Sun vectors, ecliptic J2000 [AU].
    observer_ecliptic_au
        (N, 3) target-to-observer vectors, ecliptic J2000 [AU].
    calibrated
        True for calibrated photometry (flag 1), False for relative (flag 0).
    """

    time_jd: F64
    brightness: F64
    sun_ecliptic_au: F64
    observer_ecliptic_au: F64
    calibrated: bool


def _numbers(line: str, count: int, lineno: int, src: str, what: str) -> list[float]:
    cells = line.split()
    if len(cells) != count:
        raise InputError(
            f"line {lineno}: {len(cells)} numbers, {what} has {count}: '{line.strip()}'",
            source=src,
            field=FIELD,
        )
    try:
        values = [float(c.replace("D", "E").replace("d", "e")) for c in cells]
    except ValueError:
        raise InputError(
            f"line {lineno}: '{line.strip()}' is not {count} numbers ({what})",
            source=src,
            field=FIELD,
        ) from None
    if not all(np.isfinite(values)):
        raise InputError(
            f"line {lineno}: non-finite number in '{line.strip()}'", source=src, field=FIELD
        )
    return values


def read_damit_lc(path: str | Path) -> list[DamitLightCurve]:
    """Read a DAMIT ``.lc`` file (module doc).

    Raises
    ------
    InputError
        Naming the file and line: a count that does not match the lines that follow, a
        flag other than 0 or 1, a line that is not 8 numbers, a negative brightness, a
        zero Sun or observer vector.
    """
    src = str(path)
    lines = [
        (k, line)
        for k, line in enumerate(
            read_user_text(Path(path), FIELD, what="light curves").splitlines(), 1
        )
        if line.strip()
    ]
    if not lines:
        raise InputError(
            "the file is empty (a DAMIT .lc file starts with the number of light curves)",
            source=src,
            field=FIELD,
        )
    k0, first = lines[0]
    n_curves = _count(first, k0, src, "the number of light curves")
    pos, curves = 1, list[DamitLightCurve]()
    for _ in range(n_curves):
        if pos >= len(lines):
            raise InputError(
                f"the file announces {n_curves} light curves and ends after {len(curves)}",
                source=src,
                field=FIELD,
            )
        kh, header = lines[pos]
        n, flag = _numbers(header, 2, kh, src, "a light-curve header 'N flag'")
        if n != int(n) or n < 1 or flag not in (0.0, 1.0):
            raise InputError(
                f"line {kh}: header '{header.strip()}' must be 'N flag' with N >= 1 points "
                "and flag 0 (relative) or 1 (calibrated)",
                source=src,
                field=FIELD,
            )
        rows = lines[pos + 1 : pos + 1 + int(n)]
        if len(rows) < int(n):
            raise InputError(
                f"line {kh}: the light curve announces {int(n)} points, the file "
                f"holds {len(rows)} more lines",
                source=src,
                field=FIELD,
            )
        data = np.array(
            [_numbers(r, 8, k, src, "a point 'JD I sx sy sz ex ey ez'") for k, r in rows]
        )
        _check_points(data, [k for k, _ in rows], src)
        curves.append(
            DamitLightCurve(data[:, 0], data[:, 1], data[:, 2:5], data[:, 5:8], flag == 1)
        )
        pos += 1 + int(n)
    if pos != len(lines):
        raise InputError(
            f"line {lines[pos][0]}: {len(lines) - pos} lines after the "
            f"{n_curves} announced light curves",
            source=src,
            field=FIELD,
        )
    return curves


def _count(line: str, lineno: int, src: str, what: str) -> int:
    (value,) = _numbers(line, 1, lineno, src, what)
    if value != int(value) or value < 1:
        raise InputError(
            f"line {lineno}: {what} must be a whole number >= 1, got '{line.strip()}'",
            source=src,
            field=FIELD,
        )
    return int(value)


def _check_points(data: F64, linenos: list[int], src: str) -> None:
    for col, what in ((1, "brightness"),):
        bad = np.flatnonzero(data[:, col] < 0.0)
        if bad.size:
            raise InputError(
                f"line {linenos[bad[0]]}: {what} {data[bad[0], col]} must be >= 0 "
                "(intensities, not magnitudes)",
                source=src,
                field=FIELD,
            )
    for cols, what in ((slice(2, 5), "Sun"), (slice(5, 8), "observer")):
        zero = np.flatnonzero(np.linalg.norm(data[:, cols], axis=1) == 0.0)
        if zero.size:
            raise InputError(
                f"line {linenos[zero[0]]}: the {what} vector is zero", source=src, field=FIELD
            )


def format_damit_lc(curves: list[DamitLightCurve]) -> str:
    """The text of a ``.lc`` file holding ``curves`` (full double precision)."""
    out = [f"{len(curves)}"]
    for c in curves:
        out.append(f"{c.time_jd.size} {1 if c.calibrated else 0}")
        for t, b, s, e in zip(
            c.time_jd, c.brightness, c.sun_ecliptic_au, c.observer_ecliptic_au, strict=True
        ):
            out.append(" ".join(f"{x:.17g}" for x in (t, b, *s, *e)))
    return "\n".join(out) + "\n"


def write_damit_lc(path: str | Path, curves: list[DamitLightCurve]) -> Path:
    """Write ``curves`` as a DAMIT ``.lc`` file; returns the path."""
    p = Path(path)
    p.write_text(format_damit_lc(curves))
    return p
