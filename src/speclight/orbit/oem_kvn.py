"""The KVN (keyword = value) form of a CCSDS OEM (CCSDS 502.0-B-2, sec. 5), read into segments.

Header lines (``CCSDS_OEM_VERS = 2.0`` ...), then per segment ``META_START``, ``KEY = value``
lines, ``META_STOP``, data lines (blank-separated), optionally ``COVARIANCE_START`` ..
``COVARIANCE_STOP`` (skipped); ``COMMENT`` lines anywhere. Values are checked by
:mod:`speclight.orbit.oem`.
"""

from __future__ import annotations

from speclight.errors import InputError
from speclight.orbit.oem_xml import RawSegment


def parse_oem_kvn(text: str, p: str) -> tuple[str, list[RawSegment]]:
    """``(version, segments)`` of an OEM in KVN; InputError naming the line at fault."""
    version = ""
    raw: list[RawSegment] = []
    meta: dict[str, str] | None = None
    meta_line = ""
    rows: list[tuple[str, list[str]]] = []
    in_cov = False
    for lineno, line in enumerate(text.splitlines(), start=1):
        s = line.strip()
        if not s or s.startswith("COMMENT"):
            continue
        if in_cov:
            in_cov = s != "COVARIANCE_STOP"
            continue
        if s == "COVARIANCE_START":
            in_cov = True
        elif s == "META_START":
            if meta is not None and meta_line:
                raw.append(RawSegment(meta, meta_line, rows))
            meta, meta_line, rows = {}, f"line {lineno}", []
        elif s == "META_STOP":
            if meta is None:
                raise _line_error(p, lineno, s, "META_STOP without META_START")
        elif "=" in s and (meta is None or not rows):
            key, _, value = s.partition("=")
            key = key.strip().upper()
            if key == "CCSDS_OEM_VERS":
                version = value.strip()
            elif meta is not None:
                meta[key] = value.strip()
        else:
            if meta is None:
                raise _line_error(p, lineno, s, "a data line before any META_START block")
            rows.append((f"line {lineno}", s.split()))
    if in_cov:
        raise InputError("COVARIANCE_START without COVARIANCE_STOP", source=p)
    if meta is not None:
        raw.append(RawSegment(meta, meta_line, rows))
    if not version:
        raise InputError(
            "no CCSDS_OEM_VERS line: not a CCSDS OEM (KVN) file", source=p, field="CCSDS_OEM_VERS"
        )
    return version, raw


def _line_error(p: str, lineno: int, line: str, what: str) -> InputError:
    return InputError(f"line {lineno}: {what}: {line[:80]!r}", source=p)
