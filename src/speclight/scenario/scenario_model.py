"""The top-level :class:`Scenario` model."""

from __future__ import annotations

from pydantic import Field, model_validator

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
    attitude: Attitude | None = Field(
        default=None,
        description="Needed to render a target; left out (geometry only), the body frame is "
        "the GCRS (a fixed attitude with quaternion [1, 0, 0, 0])",
    )
    target: Target | None = None
    illumination: Illumination = Field(default_factory=Illumination)
    atmosphere: Atmosphere = Field(default_factory=Atmosphere)
    spectrum: Spectrum = Field(default_factory=Spectrum)
    render: Render = Field(default_factory=Render)
    instrument: Instrument = Field(default_factory=Instrument)

    @model_validator(mode="after")
    def _attitude_where_rendered(self) -> Scenario:
        if self.attitude is None and (self.target is not None or self.render.mode == "map"):
            needs = "target" if self.target is not None else "render.mode: map"
            raise ValueError(
                f"attitude: missing, and the {needs} needs one (the target is rendered in "
                "its body frame): give e.g. attitude: {model: fixed, quaternion: [1, 0, 0, 0]}; "
                "only a geometry-only scenario (no target) may leave it out"
            )
        return self
