"""The top-level :class:`Scenario` model."""

from __future__ import annotations

from pydantic import Field

from speclight.scenario.sections_attitude import Attitude
from speclight.scenario.sections_geometry import (
    Observer,
    Orbit,
    Strict,
    Telescope,
    TimeGrid,
)
from speclight.scenario.sections_light import (
    Atmosphere,
    Illumination,
    Instrument,
    Render,
    Spectrum,
    Target,
)


class Scenario(Strict):
    """One simulation: when, from where, which target, how it turns and how it is seen."""

    name: str = Field(min_length=1, pattern=r"^[A-Za-z0-9_.\-]+$")
    description: str = ""
    time: TimeGrid
    observer: Observer
    telescope: Telescope = Field(default_factory=Telescope)
    orbit: Orbit
    attitude: Attitude
    target: Target | None = None
    illumination: Illumination = Field(default_factory=Illumination)
    atmosphere: Atmosphere = Field(default_factory=Atmosphere)
    spectrum: Spectrum = Field(default_factory=Spectrum)
    render: Render = Field(default_factory=Render)
    instrument: Instrument = Field(default_factory=Instrument)
