"""A bounded property-based fuzz of scenario and input-file handling (issue 9).

Property: whatever a user writes, speclight answers with a result or an ``InputError``;
never another exception (an internal error, exit 1 with a traceback). The strategies mutate
the built-in example scenarios: values of the wrong type, out of range, inf/nan, huge and
tiny numbers, random strings, unknown and missing keys, wrong nesting, corrupted YAML text,
and input files (orbit, mesh, material, band, detector, atmosphere tables) that are binary,
empty, latin-1 or truncated. A scenario that loads goes through the cheap stages on three
epochs: geometry, the target (meshes and materials are read), the atmosphere and the
instrument (band and detector files are read) on a zero intensity; rendering is left out
(seconds per example). A smaller property runs the command line and asserts exit 0 or 2
without a traceback.

Bounded: fixed examples (``derandomize``), ``max_examples`` and ``deadline`` set, no example
database; the file runs in about 25 s on 2 cores (``SPECLIGHT_FUZZ_EXAMPLES=2000`` to explore
further). The internal errors it found (``time.step_s: inf``, epochs outside DE421, unbounded
noise parameters: repro fuzz/0022, 0029-0033, 0246) are fixed; nothing is excluded.
"""

from __future__ import annotations

import copy
import math
import os
import tempfile
from datetime import UTC, datetime, timedelta
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from speclight.cli import app
from speclight.errors import InputError
from speclight.scenario import example_names, example_text, load_scenario
from speclight.simulation.geometry_stage import scenario_geometry
from speclight.simulation.radiometry import (
    atmosphere_transmission,
    instrument_response,
    wavelength_grid_nm,
)
from speclight.simulation.reflection import build_target

EXAMPLES = {name: yaml.safe_load(example_text(name)) for name in example_names()}
#: A scenario's own time grid is used up to this many epochs; beyond, three epochs 30 s apart.
MAX_GRID_EPOCHS = 2000
EPOCH_OFFSETS_S = np.array([0, 30, 60])
FUZZ = settings(
    max_examples=int(os.environ.get("SPECLIGHT_FUZZ_EXAMPLES", "200")),  # more to explore
    deadline=timedelta(seconds=10),
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
CLI_FUZZ = settings(FUZZ, max_examples=15)

# --- values ----------------------------------------------------------------------------

NUMBERS = st.one_of(
    st.sampled_from([0, -1, 1e308, -1e308, 5e-324, 1e-300, 2**63, -(2**63), 2**64, 10**30]),
    st.sampled_from([math.inf, -math.inf, math.nan]),
    st.integers(),
    st.floats(allow_nan=True, allow_infinity=True),
)
TEXT = st.one_of(
    st.text(max_size=20),
    st.sampled_from(["", " ", "none", "auto", "é", "\x00", "../../etc/passwd", "a" * 300]),
)
DATES = st.datetimes(datetime(1, 1, 1), datetime(9999, 12, 31), timezones=st.just(UTC))
SCALARS = st.one_of(NUMBERS, TEXT, st.booleans(), st.none(), DATES)
BAD_VALUES = st.one_of(
    SCALARS,
    st.lists(SCALARS, max_size=4),
    st.dictionaries(st.text(max_size=8), SCALARS, max_size=3),
)

# --- input files -----------------------------------------------------------------------

_TLE = EXAMPLES["calsphere"]["orbit"]["tle"]
_CSV = "wavelength_nm,value\n400,0.5\n600,0.6\n800,0.7\n1000,0.6\n"
_CPF = "H1 CPF  2 SPC 2020 11 27 00      1 lageos1\nH9\n10 0 59180 0.0 0 7000000.0 0 0\n99\n"
_EPHEMERIS = (
    "time_utc,x_m,y_m,z_m\n2020-02-29T21:13:00Z,7000000,0,0\n2020-02-29T21:23:00Z,0,7000000,0\n"
)
_OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n"
_TABLE = "wavelength_nm,1.0,2.0\n300,0.5,0.3\n1240,0.9,0.8\n"
_LAMBERTIAN = {"bsdf": "lambertian", "reflectance": 0.5}


def _file_slots() -> dict[str, tuple[str, Any]]:
    """Where a file goes in a scenario: name -> (a valid content to spoil, how to put it)."""

    def orbit(key: str) -> Any:
        return lambda data, path: data.__setitem__("orbit", {key: path})

    def first_material(data: dict[str, Any]) -> dict[str, Any]:
        target = data.setdefault("target", copy.deepcopy(EXAMPLES["calsphere"]["target"]))
        return target["materials"][next(iter(target["materials"]))]

    def reflectance(data: dict[str, Any], path: str) -> None:
        first_material(data)["reflectance"] = {"file": path}

    def brdf(data: dict[str, Any], path: str) -> None:
        m = first_material(data)
        m.clear()
        m.update(bsdf="measured", brdf_table=path)

    def mesh(data: dict[str, Any], path: str) -> None:
        data["target"] = {"shape": {"mesh_file": path}, "materials": {"*": dict(_LAMBERTIAN)}}

    def band(data: dict[str, Any], path: str) -> None:
        data.setdefault("instrument", {})["bands"] = [{"name": "T", "file": path}]

    def qe(data: dict[str, Any], path: str) -> None:
        data.setdefault("instrument", {})["detector_qe"] = path

    def table(data: dict[str, Any], path: str) -> None:
        data["atmosphere"] = {"model": "table", "table_file": path}

    return {
        "tle.txt": (_TLE, orbit("tle_file")),
        "pass.cpf": (_CPF, orbit("cpf_file")),
        "ephemeris.csv": (_EPHEMERIS, orbit("ephemeris_file")),
        "part.obj": (_OBJ, mesh),
        "reflectance.csv": (_CSV, reflectance),
        "brdf.csv": ("phi_i,theta_i,phi_o,theta_o,brdf\n0,0,0,0,0.3\n", brdf),
        "band.csv": (_CSV, band),
        "qe.csv": (_CSV, qe),
        "airmass.csv": (_TABLE, table),
    }


FILE_SLOTS = _file_slots()


@st.composite
def bad_file(draw: st.DrawFn) -> tuple[str, bytes]:
    """A file name and content: binary, empty, latin-1, truncated, or spoilt text."""
    name = draw(st.sampled_from(sorted(FILE_SLOTS)))
    valid = FILE_SLOTS[name][0]
    kind = draw(st.sampled_from(["binary", "empty", "latin-1", "truncated", "edited", "valid"]))
    if kind == "binary":
        content = draw(st.binary(min_size=1, max_size=200))
    elif kind == "empty":
        content = b""
    elif kind == "latin-1":
        content = valid.replace("0", "é", 1).encode("latin-1")
    elif kind == "truncated":
        content = valid.encode()[: draw(st.integers(0, len(valid) - 1))]
    elif kind == "edited":
        lines = valid.splitlines()
        i = draw(st.integers(0, len(lines) - 1))
        lines[i] = draw(st.sampled_from(["nan,nan", "inf,1e309", "1,2,3,4,5,6", "x", "-1,-1"]))
        content = "\n".join(lines).encode()
    else:
        content = valid.encode()
    return name, content


# --- mutations of the scenario mapping --------------------------------------------------


def _leaves(node: Any, kinds: tuple[type, ...]) -> list[tuple[Any, ...]]:
    """Key paths of the leaves of the given types (bool aside)."""
    return [
        p for p in _paths(node) if isinstance(v := _get(node, p), kinds) and not isinstance(v, bool)
    ]


def _get(data: Any, path: tuple[Any, ...]) -> Any:
    for part in path:
        data = data[part]
    return data


def _paths(node: Any, prefix: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    """Every key path into a scenario mapping (dict keys and list indices)."""
    out = [prefix] if prefix else []
    if isinstance(node, dict):
        for k, v in node.items():
            out += _paths(v, (*prefix, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            out += _paths(v, (*prefix, i))
    return out


def _parent(data: Any, path: tuple[Any, ...]) -> Any:
    for part in path[:-1]:
        data = data[part]
    return data


@st.composite
def mutated(draw: st.DrawFn, files: bool = True) -> tuple[dict[str, Any], list[tuple[str, bytes]]]:
    """An example scenario with one to three mutations, and the input files it names."""
    data = copy.deepcopy(EXAMPLES[draw(st.sampled_from(sorted(EXAMPLES)))])
    written: list[tuple[str, bytes]] = []
    for _ in range(draw(st.integers(1, 2))):
        kind = draw(st.sampled_from(MUTATIONS))
        paths = {
            "number": _leaves(data, (int, float)),
            "date": _leaves(data, (datetime,)),
            "name": _leaves(data, (str,)),
        }.get(kind) or _paths(data)
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        parent = _parent(data, path)
        key = path[-1]
        if kind == "number":
            parent[key] = draw(NUMBERS)
        elif kind == "date":
            parent[key] = draw(DATES)
        elif kind == "name":
            parent[key] = draw(TEXT)
        elif kind == "value":
            parent[key] = draw(BAD_VALUES)
        elif kind == "delete":
            del parent[key]
        elif kind == "unknown" and isinstance(parent, dict):
            parent[draw(st.text(min_size=1, max_size=12))] = draw(SCALARS)
        elif kind == "nest":
            parent[key] = draw(st.sampled_from([[parent[key]], {"value": parent[key]}]))
        elif kind == "file" and files:
            name, content = draw(bad_file())
            FILE_SLOTS[name][1](data, name)
            written.append((name, content))
    return data, written


#: Mutation kinds, repeated to weight them: mostly values of the right type (which pass the
#: type checks and reach the ranges and the stages), then wrong types, keys and files.
MUTATIONS = ["number"] * 4 + ["date", "name", "value", "delete", "unknown", "nest"] + ["file"] * 3


def _text(data: dict[str, Any]) -> str:
    return yaml.safe_dump(data, sort_keys=False, allow_unicode=True)


def _cheap_stages(scenario_file: Path) -> None:
    """Load the scenario and run its stages but rendering on at most a short time grid."""
    loaded = load_scenario(scenario_file)
    sc = loaded.scenario
    epochs = None
    if (sc.time.stop - sc.time.start).total_seconds() / sc.time.step_s + 1 > MAX_GRID_EPOCHS:
        start = np.datetime64(sc.time.start.replace(tzinfo=None), "ns")
        epochs = start + EPOCH_OFFSETS_S * np.timedelta64(1, "s")
    geo = scenario_geometry(loaded, epochs)
    if sc.target is not None:
        build_target(loaded)
    wavelength_nm = wavelength_grid_nm(sc.spectrum)
    if sc.atmosphere.model == "6s":
        return  # a cold 6S run takes seconds; tests/atmosphere covers its inputs
    elevation = np.where(geo.observable, geo.elevation_deg, np.nan)
    transmission = atmosphere_transmission(loaded, wavelength_nm, elevation)
    intensity = np.zeros((geo.flags.size, wavelength_nm.size))
    instrument_response(loaded, wavelength_nm, intensity, transmission, geo.range_m)


def _write(folder: Path, data: dict[str, Any], files: list[tuple[str, bytes]]) -> Path:
    for name, content in files:
        (folder / name).write_bytes(content)
    path = folder / "scenario.yaml"
    path.write_text(_text(data), encoding="utf-8")
    return path


@FUZZ
@given(mutated())
def test_mutated_scenarios_load_and_run_or_raise_input_error(
    case: tuple[dict[str, Any], list[tuple[str, bytes]]],
) -> None:
    data, files = case
    with tempfile.TemporaryDirectory() as folder:
        try:
            _cheap_stages(_write(Path(folder), data, files))
            event("ran")
        except InputError as exc:  # the answer to a user mistake; any other fails the property
            event(f"InputError at {exc.field or 'load'}")


@st.composite
def corrupted_text(draw: st.DrawFn) -> bytes:
    """An example's YAML text cut, spliced with random characters, or re-encoded."""
    text = example_text(draw(st.sampled_from(sorted(EXAMPLES))))
    kind = draw(st.sampled_from(["cut", "insert", "latin-1", "binary", "empty"]))
    if kind == "cut":
        return text.encode()[: draw(st.integers(0, len(text)))]
    if kind == "insert":
        at = draw(st.integers(0, len(text)))
        return (text[:at] + draw(st.text(min_size=1, max_size=10)) + text[at:]).encode()
    if kind == "latin-1":
        return text.replace("Calsphere", "Cälsphère").encode("latin-1", errors="replace")
    if kind == "binary":
        return draw(st.binary(max_size=300))
    return b""


@FUZZ
@given(corrupted_text())
def test_corrupted_scenario_text_loads_or_raises_input_error(content: bytes) -> None:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "scenario.yaml"
        path.write_bytes(content)
        try:
            _cheap_stages(path)
            event("ran")
        except InputError:
            event("InputError")


runner = CliRunner()


@st.composite
def short_cli_scenario(draw: st.DrawFn) -> tuple[dict[str, Any], list[tuple[str, bytes]]]:
    """A mutated example cut to one epoch and without a target: no rendering."""
    data, files = draw(mutated())
    if isinstance(data.get("time"), dict) and "start" in data["time"]:
        data["time"]["stop"] = data["time"]["start"]  # one epoch
    data.pop("target", None)
    return data, files


@CLI_FUZZ
@given(short_cli_scenario())
def test_cli_exits_0_or_2_without_traceback(
    case: tuple[dict[str, Any], list[tuple[str, bytes]]],
) -> None:
    data, files = case
    with tempfile.TemporaryDirectory() as folder:
        scenario = _write(Path(folder), data, files)
        result = runner.invoke(app, ["simulate", str(scenario), "-o", f"{folder}/out.nc", "-q"])
    event(f"exit {result.exit_code}")
    assert result.exit_code in (0, 2), result.output
    assert "Traceback" not in result.output


@CLI_FUZZ
@given(mutated())
def test_passes_exits_0_or_2_without_traceback(
    case: tuple[dict[str, Any], list[tuple[str, bytes]]],
) -> None:
    """``speclight passes`` reads the same scenario file (its window, site and orbit)."""
    data, files = case
    data.pop("target", None)
    with tempfile.TemporaryDirectory() as folder:
        scenario = _write(Path(folder), data, files)
        result = runner.invoke(app, ["passes", str(scenario), "-o", f"{folder}/passes.csv"])
    event(f"exit {result.exit_code}")
    assert result.exit_code in (0, 2), result.output
    assert "Traceback" not in result.output
