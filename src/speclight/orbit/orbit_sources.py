"""The orbit sources: one table read by every part that needs to know them.

A scenario's ``orbit`` section names exactly one source of the target's trajectory by its
key (``tle``, ``tle_file``, ``cpf_file``, ...). :data:`ORBIT_SOURCES` maps each key to what
the rest of speclight needs (STYLE.md item 13, as colour's method registries):

* the scenario's validation (:class:`speclight.scenario.sections_geometry.Orbit`): which
  keys are sources, which options belong to which source, the message listing them all;
* the geometry stage (:func:`orbit_trajectory`, the one front door): the reader and
  interpolator of each source;
* the output's provenance (:mod:`speclight.simulation.input_hashes`, and the geometry cache
  key of ``speclight sweep``): which keys name a file whose bytes are hashed;
* messages, field descriptions and ``docs/scenario.md`` (a test checks the table there).

Adding a source is one entry here, its reader module, and its field in the ``Orbit`` model
(the test ``tests/orbit/test_orbit_sources.py`` checks that model and table agree).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError

#: ``t -> (r_gcrs_m (N, 3), ok (N,))``: the target's GCRS position at skyfield times ``t``
#: and whether the source gives one there (epochs outside a table: False, never
#: extrapolated).
Trajectory = Callable[[Any], tuple[NDArray[np.float64], NDArray[np.bool_]]]


@dataclass(frozen=True)
class SourceRequest:
    """What a source's loader is given.

    Attributes
    ----------
    value
        The value of the source's key in the scenario (TLE text, a file name).
    path
        The file it names, resolved against the scenario's folder (None where the source
        reads no file).
    options
        The source's options as given (``{"norad_id": 25544}``; None where left out).
    time_utc
        The run's epochs, UTC ``datetime64[ns]`` (a TLE file's set is chosen by them).
    source
        Where the scenario came from, for messages.
    """

    value: Any
    path: Path | None
    options: Mapping[str, Any]
    time_utc: NDArray[np.datetime64]
    source: str


Loader = Callable[[SourceRequest], Trajectory]


@dataclass(frozen=True)
class OrbitSource:
    """One source of the target's trajectory.

    Attributes
    ----------
    key
        The ``orbit`` field that selects it.
    label
        Its name in messages ("OEM file").
    description
        One line for messages and the scenario model's field description.
    reads_file
        The key's value names a file (its SHA-256 goes into the output's ``input_files``).
    options
        ``orbit`` fields used only with this source, to choose in it (``norad_id``).
    selects
        What the options choose, for messages ("an object").
    load
        Reads the source once and returns its :data:`Trajectory`; None for a source that
        has no trajectory of its own (then ``no_load`` says where the positions come from).
    no_position
        Why a window can get no valid position from it (the message when none is valid).
    no_load
        For a source without ``load``: the message when a run asks it for a trajectory.
    """

    key: str
    label: str
    description: str
    reads_file: bool
    load: Loader | None
    no_position: str = ""
    options: tuple[str, ...] = ()
    selects: str = ""
    no_load: str = ""


def _sgp4(tle: Any, time_utc: NDArray[np.datetime64]) -> Trajectory:
    from speclight.orbit.staleness import warn_tle_age
    from speclight.orbit.tle import tle_position_gcrs_m

    warn_tle_age(tle.epoch, time_utc, float(tle.line2[52:63]))  # mean motion [rev/day]
    return lambda t: tle_position_gcrs_m(tle, t)


def _load_tle(req: SourceRequest) -> Trajectory:
    from speclight.orbit.tle import parse_tle

    return _sgp4(parse_tle(req.value, source=f"{req.source}: orbit.tle"), req.time_utc)


def _load_tle_file(req: SourceRequest) -> Trajectory:
    from speclight.orbit.tle import read_tle_file

    assert req.path is not None
    # of several element sets of the object, the one nearest the middle of the window
    middle = req.time_utc[0] + (req.time_utc[-1] - req.time_utc[0]) / 2
    tle = read_tle_file(req.path, norad_id=req.options.get("norad_id"), near_epoch=middle)
    return _sgp4(tle, req.time_utc)


def _load_cpf(req: SourceRequest) -> Trajectory:
    from speclight.orbit.cpf import cpf_position_gcrs_m, read_cpf

    assert req.path is not None
    cpf = read_cpf(req.path)
    return lambda t: cpf_position_gcrs_m(cpf, t)


def _load_ephemeris(req: SourceRequest) -> Trajectory:
    from speclight.orbit.ephemeris import ephemeris_position_gcrs_m, read_ephemeris_csv

    assert req.path is not None
    eph = read_ephemeris_csv(req.path)
    return lambda t: ephemeris_position_gcrs_m(eph, t)


def _load_oem(req: SourceRequest) -> Trajectory:
    from speclight.orbit.oem import oem_position_gcrs_m, read_oem

    assert req.path is not None
    oem = read_oem(req.path, req.options.get("object"))
    return lambda t: oem_position_gcrs_m(oem, t)


def _load_sp3(req: SourceRequest) -> Trajectory:
    from speclight.orbit.sp3 import read_sp3, sp3_position_gcrs_m

    assert req.path is not None
    sp3 = read_sp3(req.path, req.options.get("satellite"))
    return lambda t: sp3_position_gcrs_m(sp3, t)


def _tabulated(label: str) -> str:
    return (
        f"outside the span of the {label}, inside a gap of its table or around its unusable records"
    )


_SGP4_FAILED = "SGP4 failed at every epoch (a decayed orbit or an element set in error)"

#: Every orbit source, by the ``orbit`` key that selects it (see the module docstring).
ORBIT_SOURCES: Mapping[str, OrbitSource] = MappingProxyType(
    {
        s.key: s
        for s in (
            OrbitSource(
                key="tle",
                label="TLE",
                description="Two- or three-line element set (SGP4)",
                reads_file=False,
                load=_load_tle,
                no_position=_SGP4_FAILED,
            ),
            OrbitSource(
                key="tle_file",
                label="TLE file",
                description="File of TLEs; pick one by norad_id (SGP4)",
                reads_file=True,
                load=_load_tle_file,
                no_position=_SGP4_FAILED,
                options=("norad_id",),
                selects="a TLE",
            ),
            OrbitSource(
                key="cpf_file",
                label="CPF file",
                description="ILRS CPF prediction (v1 or v2)",
                reads_file=True,
                load=_load_cpf,
                no_position=_tabulated("CPF file"),
            ),
            OrbitSource(
                key="ephemeris_file",
                label="ephemeris file",
                description="CSV: time_utc, x, y, z (GCRS or ITRF)",
                reads_file=True,
                load=_load_ephemeris,
                no_position=_tabulated("ephemeris file"),
            ),
            OrbitSource(
                key="oem_file",
                label="OEM file",
                description="CCSDS OEM, KVN or XML",
                reads_file=True,
                load=_load_oem,
                no_position=_tabulated("OEM file"),
                options=("object",),
                selects="an object",
            ),
            OrbitSource(
                key="sp3_file",
                label="SP3 file",
                description="IGS SP3-c or SP3-d precise orbit",
                reads_file=True,
                load=_load_sp3,
                no_position=_tabulated("SP3 file"),
                options=("satellite",),
                selects="a satellite",
            ),
            OrbitSource(
                key="observed",
                label="observed positions",
                description="No orbit: `speclight compare` places the target where each "
                "observation saw it (elevation_deg, azimuth_deg, range_m or height_m)",
                reads_file=False,
                load=None,
                no_position="no observation placed the target within reach of these epochs",
                no_load="observed: true has no orbit of its own: the positions come from an "
                "observations file (speclight compare SCENARIO OBSERVATIONS)",
            ),
        )
    }
)


def source_keys(*, loadable: bool = False) -> tuple[str, ...]:
    """The keys of :data:`ORBIT_SOURCES` (``loadable``: only those with a trajectory of
    their own, that ``speclight simulate`` can run)."""
    return tuple(k for k, s in ORBIT_SOURCES.items() if s.load is not None or not loadable)


def choices_text(*, loadable: bool = False) -> str:
    """The sources for a message: ``tle, tle_file, ..., sp3_file or observed: true``."""
    names = [f"{k}: true" if k == "observed" else k for k in source_keys(loadable=loadable)]
    return f"{', '.join(names[:-1])} or {names[-1]}"


def file_keys() -> frozenset[str]:
    """The keys whose value names a file (hashed in the output's ``input_files``)."""
    return frozenset(k for k, s in ORBIT_SOURCES.items() if s.reads_file)


def orbit_problem(values: Mapping[str, Any]) -> str | None:
    """Why an ``orbit`` section's values do not select one source with its own options, or
    None. ``values``: the section's fields (a missing or false/None/empty value is not
    given)."""
    given = [k for k in ORBIT_SOURCES if values.get(k)]
    if len(given) != 1:
        found = ", ".join(given) if given else "none"
        return f"give exactly one of {choices_text()} (found {found})"
    for key, src in ORBIT_SOURCES.items():
        for option in src.options:
            if values.get(option) is not None and key not in given:
                return f"{option} selects {src.selects} of {key}; it needs {key}"
    return None


def selected_source(values: Mapping[str, Any]) -> OrbitSource:
    """The one source an ``orbit`` section gives (validated: see :func:`orbit_problem`)."""
    problem = orbit_problem(values)
    if problem is not None:
        raise InputError(problem, field="orbit")
    return next(s for k, s in ORBIT_SOURCES.items() if values.get(k))


def orbit_trajectory(
    values: Mapping[str, Any],
    resolve: Callable[[str], Path],
    time_utc: NDArray[np.datetime64],
    source: str,
) -> Trajectory:
    """Read the scenario's orbit source once; return its :data:`Trajectory`.

    Parameters
    ----------
    values
        The ``orbit`` section's fields (``Orbit.model_dump()``).
    resolve
        Turns a file name of the scenario into a path (relative to the scenario's folder).
    time_utc
        The run's epochs, UTC ``datetime64``.
    source
        Where the scenario came from, for messages.

    Raises
    ------
    InputError
        A source without a trajectory of its own (``observed: true``), or one whose file
        cannot be read.
    """
    src = selected_source(values)
    if src.load is None:
        raise InputError(
            f"{src.no_load}; for speclight simulate, give {choices_text(loadable=True)}",
            source=source,
            field=f"orbit.{src.key}",
        )
    value = values[src.key]
    request = SourceRequest(
        value=value,
        path=resolve(str(value)) if src.reads_file else None,
        options={o: values.get(o) for o in src.options},
        time_utc=np.asarray(time_utc, dtype="datetime64[ns]"),
        source=source,
    )
    return src.load(request)


def no_position_message(values: Mapping[str, Any]) -> str:
    """The message when the orbit gives no valid position in the window."""
    src = selected_source(values)
    why = src.no_position or "the source gives none there"
    return f"the orbit ({src.key}: {src.label}) gives no valid position in the time window: {why}"
