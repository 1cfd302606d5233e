"""The passes of ``speclight passes`` as a terminal table, a CSV or a JSON file (docs/passes.md).

Times are ISO 8601 UTC to the millisecond (``2020-02-29T21:04:45.232Z``); an interval is
``START/END`` (ISO 8601 interval notation), several are separated by ``;`` in the CSV.
"""

from __future__ import annotations

import csv
import io
import json
import sys
from pathlib import Path
from typing import Any

import numpy as np

from speclight.errors import InputError
from speclight.orbit.pass_finder import Interval, Pass
from speclight.simulation.pass_search import PassSearch

#: File formats by suffix.
FORMATS = (".csv", ".json")
#: The CSV's columns, in order (docs/passes.md).
COLUMNS = (
    "pass",
    "rise_utc",
    "rise_azimuth_deg",
    "culmination_utc",
    "culmination_azimuth_deg",
    "max_elevation_deg",
    "culmination_range_m",
    "set_utc",
    "set_azimuth_deg",
    "rises_before_start",
    "sets_after_end",
    "sunlit",
    "dark_sky",
    "observable",
    "observable_s",
)


def check_passes_output(output: str) -> str:
    """The format of a passes file from its suffix (``.csv`` or ``.json``)."""
    suffix = Path(output).suffix.lower()
    if suffix not in FORMATS:
        raise InputError(
            f"--output = {output!r}: the passes are written as CSV or JSON; name the file "
            f"with one of {', '.join(FORMATS)}",
            field="--output",
        )
    return suffix


def utc_text(t: np.datetime64) -> str:
    """ISO 8601 UTC to the millisecond."""
    return f"{np.datetime_as_string(t, unit='ms')}Z"


def _intervals(spans: tuple[Interval, ...]) -> list[list[str]]:
    return [[utc_text(a), utc_text(b)] for a, b in spans]


def pass_record(number: int, p: Pass) -> dict[str, Any]:
    """One pass as plain values (the JSON's entries; the CSV's rows)."""
    return {
        "pass": number,
        "rise_utc": utc_text(p.rise_utc),
        "rise_azimuth_deg": round(p.rise_azimuth_deg, 3),
        "culmination_utc": utc_text(p.culmination_utc),
        "culmination_azimuth_deg": round(p.culmination_azimuth_deg, 3),
        "max_elevation_deg": round(p.max_elevation_deg, 3),
        "culmination_range_m": round(p.culmination_range_m, 1),
        "set_utc": utc_text(p.set_utc),
        "set_azimuth_deg": round(p.set_azimuth_deg, 3),
        "rises_before_start": p.rises_before_start,
        "sets_after_end": p.sets_after_end,
        "sunlit": _intervals(p.sunlit),
        "dark_sky": _intervals(p.dark_sky),
        "observable": _intervals(p.observable),
        "observable_s": round(p.observable_s, 3),
    }


def _header(search: PassSearch, scenario_name: str) -> dict[str, Any]:
    return {
        "scenario": scenario_name,
        "start_utc": utc_text(search.start_utc),
        "end_utc": utc_text(search.end_utc),
        "min_elevation_deg": search.min_elevation_deg,
        "max_sun_elevation_deg": search.max_sun_elevation_deg,
    }


def passes_json(search: PassSearch, scenario_name: str) -> str:
    """The search as JSON: the window, the limits and ``passes`` (a list of records)."""
    records = [pass_record(i + 1, p) for i, p in enumerate(search.passes)]
    return json.dumps({**_header(search, scenario_name), "passes": records}, indent=2) + "\n"


def passes_csv(search: PassSearch, scenario_name: str) -> str:
    """The search as CSV: ``#`` lines with the window and limits, then one row per pass."""
    out = io.StringIO()
    for key, value in _header(search, scenario_name).items():
        out.write(f"# {key}: {value}\n")
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(COLUMNS)
    for i, p in enumerate(search.passes):
        row = pass_record(i + 1, p)
        for key in ("sunlit", "dark_sky", "observable"):
            row[key] = ";".join(f"{a}/{b}" for a, b in row[key])
        writer.writerow(
            [str(row[c]).lower() if isinstance(row[c], bool) else row[c] for c in COLUMNS]
        )
    return out.getvalue()


def passes_file_bytes(search: PassSearch, scenario_name: str, suffix: str) -> bytes:
    """The file's bytes for a suffix of :data:`FORMATS`."""
    text = (
        passes_json(search, scenario_name)
        if suffix == ".json"
        else passes_csv(search, scenario_name)
    )
    return text.encode()


def _clock(t: np.datetime64) -> str:
    return np.datetime_as_string(t, unit="s")[11:]


def _spans(spans: tuple[Interval, ...]) -> str:
    return "\n".join(f"{_clock(a)}-{_clock(b)}" for a, b in spans) or "-"


def print_passes(search: PassSearch, title: str) -> None:
    """A table of the passes on the terminal (plain text when not on one)."""
    from rich.console import Console
    from rich.markup import escape
    from rich.table import Table

    table = Table(
        title=title,
        caption=(
            f"rise and set at {search.min_elevation_deg:g} deg elevation; dark sky: the Sun at "
            f"or below {search.max_sun_elevation_deg:g} deg; observable: sunlit and dark sky"
        ),
    )
    for name in (
        "#",
        "rise (UTC)",
        "culmination",
        "set",
        "max el [deg]",
        "az rise/set [deg]",
        "sunlit",
        "dark sky",
        "observable",
        "observable [s]",
    ):
        table.add_column(escape(name), justify="right" if "[" in name or name == "#" else "left")
    for i, p in enumerate(search.passes):
        rise = np.datetime_as_string(p.rise_utc, unit="s").replace("T", " ")
        table.add_row(
            str(i + 1),
            rise + (" (start)" if p.rises_before_start else ""),
            _clock(p.culmination_utc),
            _clock(p.set_utc) + (" (end)" if p.sets_after_end else ""),
            f"{p.max_elevation_deg:.1f}",
            f"{p.rise_azimuth_deg:.0f} / {p.set_azimuth_deg:.0f}",
            _spans(p.sunlit),
            _spans(p.dark_sky),
            _spans(p.observable),
            f"{p.observable_s:.0f}",
        )
    console = Console(width=None if sys.stdout.isatty() else 200)
    if not search.passes:
        console.print(f"no pass above {search.min_elevation_deg:g} deg elevation in the window")
        return
    console.print(table)
