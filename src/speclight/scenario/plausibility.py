"""Notices for scenario values far outside anything flown or built (most likely a wrong
unit): checked once when a scenario is read (:func:`speclight.scenario.parse_scenario`),
reported as :class:`~speclight.plausible_ranges.PlausibilityWarning`, never refused.

Checked: the built-in shape's sizes (every ``*_m`` field of ``target.shape``), the
telescope's aperture, the observer's and the lasers' site altitudes, each laser's average
power and pulse energy, and an inline TLE's perigee and apogee. A mesh's size is known only
when it is read (:func:`speclight.target.mesh_io.load_mesh` reports it then). The ranges and
their sources are in :mod:`speclight.plausible_ranges`.
"""

from __future__ import annotations

from collections.abc import Iterator

from speclight.errors import InputError
from speclight.plausible_ranges import (
    APOGEE_ALTITUDE_M,
    LASER_POWER_W,
    LASER_PULSE_ENERGY_J,
    PERIGEE_ALTITUDE_M,
    SITE_ALTITUDE_M,
    TARGET_SIZE_M,
    TELESCOPE_APERTURE_M,
    PlausibleRange,
    warn_implausible,
)
from speclight.scenario.scenario_model import Scenario
from speclight.scenario.sections_light import Shape

#: The length fields of a built-in shape (``scale_m_per_unit`` is a ratio, not a length).
SHAPE_LENGTHS = tuple(k for k in Shape.model_fields if k.endswith("_m"))

Check = tuple[str, float, PlausibleRange]


def _shape_sizes(shape: Shape) -> Iterator[Check]:
    for name in SHAPE_LENGTHS:
        value = getattr(shape, name)
        if value is None:
            continue
        items = enumerate(value) if isinstance(value, list) else [(None, value)]
        for i, size in items:
            field = f"target.shape.{name}" + ("" if i is None else f".{i}")
            if size != 0:  # a gap of 0 is no size; an offset is a signed length
                yield field, abs(float(size)), TARGET_SIZE_M


def _tle_altitudes(text: str) -> Iterator[Check]:
    """Perigee and apogee heights of an inline TLE (SGP4's own mean elements); nothing for
    a TLE that does not read (the run reports it)."""
    from sgp4.api import Satrec

    from speclight.orbit.tle import parse_tle

    try:
        tle = parse_tle(text)
    except InputError:
        return
    sat = Satrec.twoline2rv(tle.line1, tle.line2)
    if sat.error:
        return
    earth_radius_m = sat.radiusearthkm * 1e3  # SGP4's WGS72 radius, as its elements
    yield "orbit.tle (perigee height)", sat.altp * earth_radius_m, PERIGEE_ALTITUDE_M
    yield "orbit.tle (apogee height)", sat.alta * earth_radius_m, APOGEE_ALTITUDE_M


def plausibility_checks(scenario: Scenario) -> Iterator[Check]:
    """``(field, value, plausible range)`` of every value the scenario is checked on."""
    sc = scenario
    yield "telescope.aperture_diameter_m", sc.telescope.aperture_diameter_m, TELESCOPE_APERTURE_M
    yield "observer.altitude_m", sc.observer.altitude_m, SITE_ALTITUDE_M
    if sc.target is not None and sc.target.shape.builtin is not None:
        yield from _shape_sizes(sc.target.shape)
    for i, laser in enumerate(sc.illumination.lasers):
        base = f"illumination.lasers.{i}"
        yield f"{base}.altitude_m", laser.altitude_m, SITE_ALTITUDE_M
        yield f"{base}.power_w", laser.power_w, LASER_POWER_W
        energy_j = laser.power_w / laser.repetition_rate_hz
        yield f"{base}: pulse energy power_w / repetition_rate_hz", energy_j, LASER_PULSE_ENERGY_J
    if sc.orbit.tle:
        yield from _tle_altitudes(sc.orbit.tle)


def warn_implausible_values(scenario: Scenario) -> int:
    """Issue a :class:`~speclight.plausible_ranges.PlausibilityWarning` for every checked
    value outside its range; returns how many."""
    return sum(warn_implausible(*check) for check in plausibility_checks(scenario))
