"""The XML form of a CCSDS OEM (NDM/XML, CCSDS 505.0-B-1), read into the KVN reader's pieces.

Layout::

    <oem id="CCSDS_OEM_VERS" version="2.0">
      <header><CREATION_DATE>..</CREATION_DATE><ORIGINATOR>..</ORIGINATOR></header>
      <body>
        <segment>
          <metadata><OBJECT_NAME>..</OBJECT_NAME> ... <TIME_SYSTEM>UTC</TIME_SYSTEM> ...
          </metadata>
          <data>
            <COMMENT>..</COMMENT>
            <stateVector><EPOCH>..</EPOCH><X>..</X><Y>..</Y><Z>..</Z>
              <X_DOT>..</X_DOT><Y_DOT>..</Y_DOT><Z_DOT>..</Z_DOT></stateVector>
            <covarianceMatrix>..</covarianceMatrix>   (skipped)
          </data>
        </segment>
      </body>
    </oem>

Namespaces are ignored. A ``units`` attribute on a value must be the standard's unit (km,
km/s). Files with a DOCTYPE are refused (no entity expansion from a user's file).
"""

from __future__ import annotations

from dataclasses import dataclass
from xml.etree import ElementTree as ET

from speclight.errors import InputError

STATE_KEYS = ("EPOCH", "X", "Y", "Z", "X_DOT", "Y_DOT", "Z_DOT")
UNITS = {"X": "km", "Y": "km", "Z": "km", "X_DOT": "km/s", "Y_DOT": "km/s", "Z_DOT": "km/s"}


@dataclass(frozen=True)
class RawSegment:
    """A segment as read: metadata keys, data rows and where each came from."""

    meta: dict[str, str]
    where: str  # "line 12" or "segment 2"
    rows: list[tuple[str, list[str]]]  # (where, [epoch, x, y, z, x_dot, y_dot, z_dot, ...])


def _local(tag: str) -> str:
    return tag.rsplit("}", 1)[-1]


def _child(el: ET.Element, name: str) -> ET.Element | None:
    return next((c for c in el if _local(c.tag) == name), None)


def parse_oem_xml(text: str, p: str) -> tuple[str, list[RawSegment]]:
    """``(version, segments)`` of an OEM in XML; InputError naming what is wrong."""
    root = _root(text, p)
    version = root.get("version", "")
    body = _child(root, "body")
    if body is None:
        raise InputError("no <body> element", source=p)
    segments = (c for c in body if _local(c.tag) == "segment")
    return version, [_segment(seg, f"segment {k}", p) for k, seg in enumerate(segments, start=1)]


def _root(text: str, p: str) -> ET.Element:
    """The ``<oem>`` root element of the text (no DOCTYPE, well-formed)."""
    if "<!DOCTYPE" in text or "<!ENTITY" in text:
        raise InputError("XML with a DOCTYPE or entities is not accepted", source=p)
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise InputError(f"not well-formed XML ({exc})", source=p) from None
    if _local(root.tag) != "oem":
        raise InputError(
            f"the root element is <{_local(root.tag)}>, not <oem>: not a CCSDS OEM in XML",
            source=p,
        )
    return root


def _segment(seg: ET.Element, where: str, p: str) -> RawSegment:
    """One ``<segment>``: its metadata keys and state vectors."""
    meta_el = _child(seg, "metadata")
    data_el = _child(seg, "data")
    if meta_el is None or data_el is None:
        raise InputError(f"{where}: needs <metadata> and <data>", source=p)
    meta = {
        _local(c.tag).upper(): (c.text or "").strip() for c in meta_el if _local(c.tag) != "COMMENT"
    }
    vectors = (c for c in data_el if _local(c.tag) == "stateVector")
    rows = [
        (f"{where} stateVector {i}", _state_cells(sv, f"{where} stateVector {i}", p))
        for i, sv in enumerate(vectors, start=1)
    ]
    return RawSegment(meta, where, rows)


def _state_cells(sv: ET.Element, at: str, p: str) -> list[str]:
    """The texts of a ``<stateVector>``'s epoch and six values (units checked)."""
    cells = []
    for key in STATE_KEYS:
        el = _child(sv, key)
        if el is None:
            raise InputError(f"{at}: no <{key}>", source=p)
        unit = el.get("units")
        if unit is not None and unit.strip().lower() != UNITS[key]:
            raise InputError(
                f"{at}: <{key} units={unit!r}> is not accepted (unit {UNITS[key]})",
                source=p,
            )
        cells.append((el.text or "").strip())
    return cells
