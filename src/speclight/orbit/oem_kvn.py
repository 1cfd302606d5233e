"""The KVN (keyword = value) form of a CCSDS OEM (CCSDS 502.0-B-2, sec. 5), read into segments.

Header lines (``CCSDS_OEM_VERS = 2.0`` ...), then per segment ``META_START``, ``KEY = value``
lines, ``META_STOP``, data lines (blank-separated), optionally ``COVARIANCE_START`` ..
``COVARIANCE_STOP`` (skipped); ``COMMENT`` lines anywhere. Values are checked by
:mod:`speclight.orbit.oem`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from speclight.errors import InputError
from speclight.orbit.oem_xml import RawSegment


def parse_oem_kvn(text: str, p: str) -> tuple[str, list[RawSegment]]:
    """``(version, segments)`` of an OEM in KVN; InputError naming the line at fault."""
    kvn = _Kvn()
    for lineno, line in enumerate(text.splitlines(), start=1):
        s = line.strip()
        if not s or s.startswith("COMMENT"):
            continue
        if kvn.in_cov:
            kvn.in_cov = s != "COVARIANCE_STOP"
            continue
        _kvn_line(kvn, p, lineno, s)
    if kvn.in_cov:
        raise InputError("COVARIANCE_START without COVARIANCE_STOP", source=p)
    if kvn.meta is not None:
        kvn.raw.append(RawSegment(kvn.meta, kvn.meta_line, kvn.rows))
    if not kvn.version:
        raise InputError(
            "no CCSDS_OEM_VERS line: not a CCSDS OEM (KVN) file", source=p, field="CCSDS_OEM_VERS"
        )
    return kvn.version, kvn.raw


@dataclass
class _Kvn:
    """The file read so far: version, finished segments, the open one, covariance block."""

    version: str = ""
    raw: list[RawSegment] = field(default_factory=list)
    meta: dict[str, str] | None = None
    meta_line: str = ""
    rows: list[tuple[str, list[str]]] = field(default_factory=list)
    in_cov: bool = False


def _kvn_line(kvn: _Kvn, p: str, lineno: int, s: str) -> None:
    """One line (stripped, not a comment, outside a covariance block)."""
    if s == "COVARIANCE_START":
        kvn.in_cov = True
    elif s == "META_START":
        _start_segment(kvn, lineno)
    elif s == "META_STOP":
        if kvn.meta is None:
            raise _line_error(p, lineno, s, "META_STOP without META_START")
    elif "=" in s and (kvn.meta is None or not kvn.rows):
        _keyword(kvn, s)
    elif kvn.meta is None:
        raise _line_error(p, lineno, s, "a data line before any META_START block")
    else:
        kvn.rows.append((f"line {lineno}", s.split()))


def _start_segment(kvn: _Kvn, lineno: int) -> None:
    """``META_START``: the open segment (if any) is finished, a new one starts."""
    if kvn.meta is not None and kvn.meta_line:
        kvn.raw.append(RawSegment(kvn.meta, kvn.meta_line, kvn.rows))
    kvn.meta, kvn.meta_line, kvn.rows = {}, f"line {lineno}", []


def _keyword(kvn: _Kvn, s: str) -> None:
    """A ``KEY = value`` line: the version, or a key of the open segment's metadata."""
    key, _, value = s.partition("=")
    key = key.strip().upper()
    if key == "CCSDS_OEM_VERS":
        kvn.version = value.strip()
    elif kvn.meta is not None:
        kvn.meta[key] = value.strip()


def _line_error(p: str, lineno: int, line: str, what: str) -> InputError:
    return InputError(f"line {lineno}: {what}: {line[:80]!r}", source=p)
