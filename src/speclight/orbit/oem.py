"""CCSDS Orbit Ephemeris Message (OEM), KVN and XML.

Format: CCSDS 502.0-B-2 *Orbit Data Messages* (Blue Book, 2009; OEM version 2.0; 502.0-B-3,
2023, keeps the OEM layout and writes ``CCSDS_OEM_VERS = 3.0``) and CCSDS 505.0-B-1 (NDM/XML).
A KVN file is a header (``CCSDS_OEM_VERS``, ``CREATION_DATE``, ``ORIGINATOR``), then one or
more segments, each a ``META_START`` .. ``META_STOP`` block of ``KEY = value`` lines and
data lines ``epoch x y z x_dot y_dot z_dot [x_ddot y_ddot z_ddot]`` in km and km/s,
optionally followed by ``COVARIANCE_START`` .. ``COVARIANCE_STOP`` (skipped). ``COMMENT``
lines may appear anywhere. The XML form carries the same keys as elements
(``oem/body/segment/metadata`` and ``data/stateVector``).

Accepted: ``CENTER_NAME = EARTH``; ``REF_FRAME`` GCRF, ICRF, EME2000 (J2000), ITRF and its
realisations (ITRF2000, ITRF-93, ITRF2014, ...), TEME (treatments in
:mod:`speclight.orbit.state_table`); ``TIME_SYSTEM`` UTC, TAI, TT, GPS. Epochs are
``YYYY-MM-DDThh:mm:ss[.f]`` or ``YYYY-DDDThh:mm:ss[.f]`` with an optional ``Z``.

Interpolation: the segment's ``INTERPOLATION`` (``HERMITE``, ``LAGRANGE`` or ``LINEAR``) and
``INTERPOLATION_DEGREE``. Hermite uses the velocities every OEM data line carries: a degree
``d`` needs ``ceil((d + 1) / 2)`` nodes (value and slope at each give ``2n - 1 >= d``);
Lagrange of degree ``d`` uses ``d + 1`` nodes. Without the keys: Hermite of degree 5
(3 nodes). Measured in ``tests/orbit/test_orbit_oem.py`` at 60 s sampling of a 1,000 km
orbit: < 1 mm for exact states; 0.2 m for a file of SGP4 states, whose velocities differ
from the derivative of its positions by ~1 cm/s (Lagrange of degree 7 there: < 1 mm).
Each epoch is taken from the first segment whose usable span (``USEABLE_START_TIME`` ..
``USEABLE_STOP_TIME``, else ``START_TIME`` .. ``STOP_TIME``, and inside its data) covers it;
other epochs are orbit failures, never extrapolated.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from speclight.errors import InputError, did_you_mean
from speclight.input_files import read_user_text
from speclight.orbit.frames import EarthOrientation, TimeLike
from speclight.orbit.oem_kvn import parse_oem_kvn
from speclight.orbit.oem_xml import RawSegment, parse_oem_xml
from speclight.orbit.state_table import (
    Segment,
    as_ns,
    frame_kind,
    segments_position_gcrs_m,
    tai_julian,
)

FIELD = "orbit.oem_file"
TIME_SYSTEMS = ("UTC", "TAI", "TT", "GPS")
FRAMES_ACCEPTED = "GCRF, ICRF, EME2000 (J2000), ITRF / ITRF2000 / ITRF-93 / ITRF2014, TEME"
DEFAULT_DEGREE = 5
_DOY = re.compile(r"^(\d{4})-(\d{3})T(.*)$")


@dataclass(frozen=True)
class Oem:
    """An OEM reduced to what positions need.

    Attributes
    ----------
    path
        File read.
    version
        ``CCSDS_OEM_VERS``.
    object_name, object_id
        Of the segments kept.
    segments
        Interpolable tables, in file order.
    metadata
        The metadata keys of each kept segment, as written.
    """

    path: str
    version: str
    object_name: str
    object_id: str
    segments: list[Segment]
    metadata: list[dict[str, str]]


def parse_epoch(text: str) -> np.datetime64:
    """A CCSDS epoch (calendar or day-of-year form) as ``datetime64[ns]``; ValueError if not."""
    s = text.strip()
    if s.upper().endswith("Z"):
        s = s[:-1]
    m = _DOY.match(s)
    if "." in s:  # numpy keeps at most nanoseconds
        head, _, frac = s.partition(".")
        s = f"{head}.{frac[:9]}"
    if m:
        day = int(m.group(2))
        if not 1 <= day <= 366:
            raise ValueError(f"day of year {day} is not 1-366")
        base = as_ns(np.datetime64(f"{m.group(1)}-01-01T{s.partition('T')[2]}"))
        return base + np.timedelta64(day - 1, "D")
    if "T" not in s:
        raise ValueError("not a time")
    return as_ns(np.datetime64(s))


def read_oem(path: str | Path, object_name: str | None = None) -> Oem:
    """Read an OEM file (KVN or XML) and keep the segments of one object.

    Parameters
    ----------
    path
        The file.
    object_name
        ``OBJECT_NAME`` or ``OBJECT_ID`` of the object to keep; needed when the file holds
        several objects.

    Raises
    ------
    InputError
        Unreadable file, malformed line (named by its number), unsupported centre, frame
        or time system, unknown object (with a did-you-mean), fewer than 2 data lines in a
        segment, or epochs that do not increase.
    """
    p = str(path)
    text = read_user_text(path, FIELD, what="OEM file")
    if text.lstrip().startswith("<"):
        version, raw = parse_oem_xml(text, p)
    else:
        version, raw = parse_oem_kvn(text, p)
    if not raw:
        raise InputError("no segment (META_START .. META_STOP and data lines)", source=p)
    raw = _object_segments(p, raw, object_name)
    segments = [_segment(r, p) for r in raw]
    return Oem(
        path=p,
        version=version,
        object_name=raw[0].meta.get("OBJECT_NAME", ""),
        object_id=raw[0].meta.get("OBJECT_ID", ""),
        segments=segments,
        metadata=[r.meta for r in raw],
    )


def _object_segments(p: str, raw: list[RawSegment], object_name: str | None) -> list[RawSegment]:
    """The segments of the object named (by OBJECT_NAME or OBJECT_ID), or of the file's one
    object."""
    names = [(r.meta.get("OBJECT_NAME", ""), r.meta.get("OBJECT_ID", "")) for r in raw]
    if object_name is not None:
        return _named_segments(p, raw, names, object_name)
    if len({n[0] for n in names}) > 1:
        raise InputError(
            f"the file holds several objects ({', '.join(sorted({n[0] for n in names}))}); "
            "choose one with orbit.object",
            source=p,
            field="orbit.object",
        )
    return raw


def _named_segments(
    p: str, raw: list[RawSegment], names: list[tuple[str, str]], object_name: str
) -> list[RawSegment]:
    """The segments whose OBJECT_NAME or OBJECT_ID is ``object_name`` (case ignored)."""
    want = object_name.strip().upper()
    kept = [r for r, n in zip(raw, names, strict=True) if want in (n[0].upper(), n[1].upper())]
    if not kept:
        choices = sorted({x for n in names for x in n if x})
        raise InputError(
            f"object {object_name!r} is not in the file"
            f"{did_you_mean(object_name, choices)} (objects: {', '.join(choices)})",
            source=p,
            field="orbit.object",
        )
    return kept


def _segment(raw: RawSegment, p: str) -> Segment:
    meta = raw.meta

    def need(key: str) -> str:
        if key not in meta or not meta[key]:
            raise InputError(f"segment at {raw.where}: no {key}", source=p, field=key)
        return meta[key]

    center = need("CENTER_NAME").upper()
    if center != "EARTH":
        raise InputError(
            f"segment at {raw.where}: CENTER_NAME = {center} is not supported; speclight "
            "simulates Earth-orbiting targets (accepted: EARTH)",
            source=p,
            field="CENTER_NAME",
        )
    frame_name = need("REF_FRAME")
    frame = frame_kind(frame_name)
    if frame is None:
        raise InputError(
            f"segment at {raw.where}: REF_FRAME = {frame_name} is not supported (accepted: "
            f"{FRAMES_ACCEPTED})",
            source=p,
            field="REF_FRAME",
        )
    scale = need("TIME_SYSTEM").upper()
    if scale not in TIME_SYSTEMS:
        raise InputError(
            f"segment at {raw.where}: TIME_SYSTEM = {scale} is not supported (accepted: "
            f"{', '.join(TIME_SYSTEMS)}){did_you_mean(scale, TIME_SYSTEMS)}",
            source=p,
            field="TIME_SYSTEM",
        )
    bounds = {}
    for key in ("START_TIME", "STOP_TIME", "USEABLE_START_TIME", "USEABLE_STOP_TIME"):
        if key in meta:
            try:
                bounds[key] = parse_epoch(meta[key])
            except ValueError:
                raise InputError(
                    f"segment at {raw.where}: {key} = {meta[key]!r} is not a CCSDS time "
                    "(YYYY-MM-DDThh:mm:ss[.f] or YYYY-DDDThh:mm:ss[.f])",
                    source=p,
                    field=key,
                ) from None
    need("START_TIME"), need("STOP_TIME")
    method, n_points = _interpolation(meta, raw.where, p)
    times, states = _rows(raw, p)
    lo = max(bounds.get("USEABLE_START_TIME", bounds["START_TIME"]), times[0])
    hi = min(bounds.get("USEABLE_STOP_TIME", bounds["STOP_TIME"]), times[-1])
    outside = (times < bounds["START_TIME"]) | (times > bounds["STOP_TIME"])
    if outside.any():
        i = int(np.flatnonzero(outside)[0])
        raise InputError(
            f"{raw.rows[i][0]}: epoch {times[i]} is outside START_TIME .. STOP_TIME "
            f"({bounds['START_TIME']} .. {bounds['STOP_TIME']}) of its segment",
            source=p,
        )
    whole, frac = tai_julian(times, scale)
    lo_hi_w, lo_hi_f = tai_julian(np.array([lo, hi], dtype="datetime64[ns]"), scale)
    w0 = float(lo_hi_w[0])
    valid = (w0, float(lo_hi_f[0]), float(lo_hi_w[1] - w0 + lo_hi_f[1]))
    return Segment(
        frame=frame,
        tai_whole=whole,
        tai_fraction=frac,
        r_m=states[:, :3] * 1e3,
        v_m_s=states[:, 3:6] * 1e3,
        method=method,
        n_points=n_points,
        valid_tai=valid,
    )


def _interpolation(meta: dict[str, str], where: str, p: str) -> tuple[str, int]:
    method = meta.get("INTERPOLATION", "HERMITE").upper()
    try:
        degree = int(meta.get("INTERPOLATION_DEGREE", str(DEFAULT_DEGREE)))
        if degree < 1:
            raise ValueError
    except ValueError:
        raise InputError(
            f"segment at {where}: INTERPOLATION_DEGREE = {meta['INTERPOLATION_DEGREE']!r} is "
            "not a positive integer",
            source=p,
            field="INTERPOLATION_DEGREE",
        ) from None
    if method == "HERMITE":
        return "hermite", max(2, math.ceil((degree + 1) / 2))
    if method in ("LAGRANGE", "LINEAR"):
        return "lagrange", 2 if method == "LINEAR" else degree + 1
    raise InputError(
        f"segment at {where}: INTERPOLATION = {method} is not supported (accepted: HERMITE, "
        "LAGRANGE, LINEAR)",
        source=p,
        field="INTERPOLATION",
    )


def _rows(raw: RawSegment, p: str) -> tuple[np.ndarray, np.ndarray]:
    times = []
    states = []
    for where, cells in raw.rows:
        try:
            if len(cells) not in (7, 10):
                raise ValueError(f"{len(cells)} fields instead of 7 (or 10 with accelerations)")
            t = parse_epoch(cells[0])
            values = [float(c) for c in cells[1:7]]
            if not all(math.isfinite(v) for v in values):
                raise ValueError("a value is not finite")
        except ValueError as exc:
            raise InputError(
                f"{where}: cannot read {' '.join(cells)[:100]!r} ({exc}); expected an epoch "
                "and x y z [km] x_dot y_dot z_dot [km/s]",
                source=p,
            ) from None
        times.append(t)
        states.append(values)
    if len(times) < 2:
        raise InputError(
            f"segment at {raw.where}: {len(times)} data lines; need at least 2", source=p
        )
    t_arr = np.array(times, dtype="datetime64[ns]")
    bad = np.flatnonzero(np.diff(t_arr) <= np.timedelta64(0, "ns"))
    if bad.size:
        raise InputError(
            f"{raw.rows[bad[0] + 1][0]}: epoch {t_arr[bad[0] + 1]} is not after the previous "
            "one; epochs must increase within a segment",
            source=p,
        )
    return t_arr, np.array(states, dtype=np.float64)


def oem_position_gcrs_m(
    oem: Oem, t: TimeLike, orientation: EarthOrientation | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """GCRS position [m] (N, 3) of the OEM's object at ``t`` and the ok mask (False, NaN
    rows, outside every segment's usable span)."""
    return segments_position_gcrs_m(oem.segments, t, orientation)
