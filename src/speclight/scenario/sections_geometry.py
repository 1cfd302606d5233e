"""Pydantic models of the scenario file (docs/scenario.md).

Units are in the field names. Every model forbids unknown keys, so a misspelt key is an
error (with a did-you-mean added by :mod:`speclight.scenario.load`). The models only
validate and convert; the physics lives in the stage subpackages.
"""

from __future__ import annotations

from datetime import UTC, datetime, timedelta
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from speclight.orbit.orbit_sources import ORBIT_SOURCES, orbit_problem

MAX_EPOCHS = 10_000_000
#: Span of the JPL DE421 ephemeris shipped in skyfield-data (``de421.bsp``: every segment
#: covers Julian dates 2414864.5 .. 2471184.5 TDB, 1899-07-29 .. 2053-10-09; Folkner et al.
#: 2009, IPN Progress Report 42-178). The Sun's position, hence every run, needs it.
EPHEMERIS_SPAN_TDB_JD = (2414864.5, 2471184.5)
#: How far inside that span the time window must stay: the Sun and Earth-orientation grids
#: reach 6 hourly steps beyond the window (``GRID_PAD_STEPS`` in :mod:`speclight.orbit.frames`
#: and :mod:`speclight.orbit.sun`), the Sun is observed 8.3 min of light time earlier, and
#: TDB - UTC stays within -3 .. +100 s over the span; one day covers all of them.
EPHEMERIS_MARGIN = timedelta(days=1)


def _utc_of_jd(jd: float) -> datetime:
    """The UTC date of a Julian date, to the day (TDB - UTC is inside ``EPHEMERIS_MARGIN``)."""
    return datetime(2000, 1, 1, 12, tzinfo=UTC) + timedelta(days=jd - 2451545.0)


#: First and last accepted epoch of a time window (UTC).
FIRST_EPOCH_UTC = _utc_of_jd(EPHEMERIS_SPAN_TDB_JD[0]) + EPHEMERIS_MARGIN
LAST_EPOCH_UTC = _utc_of_jd(EPHEMERIS_SPAN_TDB_JD[1]) - EPHEMERIS_MARGIN


def _source(key: str) -> str:
    return ORBIT_SOURCES[key].description


class Strict(BaseModel):
    """Base model: unknown keys are errors, no number may be infinite or NaN (YAML's ``.inf``
    and ``.nan``: no field has a meaning for them, and they would pass a bound such as
    ``gt=0`` or slip through a range check), and fields are read-only: a scenario changes
    through :func:`speclight.scenario.overrides.with_overrides`, which validates the whole
    scenario as a file is validated (an assignment could not check the rules between
    sections, and would leave the YAML recorded in outputs behind)."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    def __setattr__(self, name: str, value: Any) -> None:
        if name.startswith("_"):  # private state a validator derives (e.g. parsed tables)
            super().__setattr__(name, value)
            return
        raise TypeError(
            f"scenario fields are read-only ({type(self).__name__}.{name} = {value!r}): use "
            "speclight.with_overrides(scenario, {'section.field': value}), which validates "
            "the whole scenario as a file is"
        )


class TimeGrid(Strict):
    """Uniform UTC time grid; ``stop`` is included when it falls on the grid."""

    start: datetime
    stop: datetime
    step_s: float = Field(gt=0, description="Time step [s]")

    @field_validator("start", "stop")
    @classmethod
    def _utc(cls, value: datetime) -> datetime:
        if value.tzinfo is None:
            return value.replace(tzinfo=UTC)
        return value.astimezone(UTC)

    @model_validator(mode="after")
    def _order(self) -> TimeGrid:
        span_s = (self.stop - self.start).total_seconds()
        if span_s < 0:
            raise ValueError(
                f"stop ({self.stop.isoformat()}) is before start ({self.start.isoformat()}); "
                "give a stop time after the start time"
            )
        if self.start < FIRST_EPOCH_UTC or self.stop > LAST_EPOCH_UTC:
            raise ValueError(
                f"the window {self.start.isoformat()} .. {self.stop.isoformat()} is outside "
                f"what the shipped Sun ephemeris (JPL DE421) covers; accepted: "
                f"{FIRST_EPOCH_UTC.date()} to {LAST_EPOCH_UTC.date()} UTC"
            )
        if span_s / self.step_s + 1 > MAX_EPOCHS:
            raise ValueError(
                f"{span_s / self.step_s + 1:.0f} epochs requested; at most {MAX_EPOCHS} are "
                "accepted: increase step_s or shorten the window"
            )
        return self


class Observer(Strict):
    """Observing site on the WGS84 ellipsoid."""

    latitude_deg: float = Field(ge=-90, le=90)
    longitude_deg: float = Field(ge=-180, le=360)
    altitude_m: float = Field(default=0.0, ge=-500, le=9000)
    min_elevation_deg: float = Field(
        default=10.0, ge=-90, le=90, description="Epochs below this elevation are flagged [deg]"
    )
    max_sun_elevation_deg: float = Field(
        default=-6.0,
        ge=-90,
        le=90,
        description="Epochs with the Sun higher at the site are flagged daylight [deg]; "
        "-6 civil, -12 nautical, -18 astronomical twilight, 90 never",
    )
    refraction: bool = Field(default=False, description="Apply atmospheric refraction to elevation")
    light_time: bool = Field(
        default=True,
        description="Place the target where it was when the received light left it",
    )
    temperature_C: float = Field(default=10.0, ge=-80, le=60)
    pressure_mbar: float | None = Field(
        default=None, ge=0, le=1100, description="Site pressure; default from the altitude [mbar]"
    )


class Telescope(Strict):
    aperture_diameter_m: float = Field(default=0.43, gt=0, le=100)
    obstruction_diameter_m: float = Field(default=0.0, ge=0)

    @model_validator(mode="after")
    def _obstruction(self) -> Telescope:
        if self.obstruction_diameter_m >= self.aperture_diameter_m:
            raise ValueError(
                f"obstruction_diameter_m = {self.obstruction_diameter_m} must be smaller than "
                f"aperture_diameter_m = {self.aperture_diameter_m}"
            )
        return self


class Orbit(Strict):
    """Exactly one source of the target's trajectory: a key of
    :data:`speclight.orbit.orbit_sources.ORBIT_SOURCES`, with that source's options."""

    tle: str | None = Field(default=None, description=_source("tle"))
    tle_file: str | None = Field(default=None, description=_source("tle_file"))
    norad_id: int | None = Field(default=None, ge=1, description="Catalogue number in tle_file")
    cpf_file: str | None = Field(default=None, description=_source("cpf_file"))
    ephemeris_file: str | None = Field(default=None, description=_source("ephemeris_file"))
    oem_file: str | None = Field(default=None, description=_source("oem_file"))
    object: str | None = Field(default=None, description="OBJECT_NAME or OBJECT_ID in oem_file")
    sp3_file: str | None = Field(default=None, description=_source("sp3_file"))
    satellite: str | None = Field(default=None, description="Vehicle id in sp3_file, e.g. G01")
    observed: bool = Field(default=False, description=_source("observed"))

    @model_validator(mode="after")
    def _exactly_one(self) -> Orbit:
        problem = orbit_problem(self.model_dump())
        if problem is not None:
            raise ValueError(problem)
        return self


Vector3 = Annotated[list[float], Field(min_length=3, max_length=3)]
Quaternion = Annotated[list[float], Field(min_length=4, max_length=4)]


class AxesOrientation(Strict):
    """Orientation of the body frame: a quaternion or RA/Dec of the body z and x axes."""

    quaternion: Quaternion | None = Field(
        default=None, description="Body-to-GCRS rotation, scalar first (w, x, y, z)"
    )
    z_axis_ra_deg: float | None = None
    z_axis_dec_deg: float | None = Field(default=None, ge=-90, le=90)
    x_axis_ra_deg: float | None = None
    x_axis_dec_deg: float | None = Field(default=None, ge=-90, le=90)

    @model_validator(mode="after")
    def _one_form(self) -> AxesOrientation:
        radec = [self.z_axis_ra_deg, self.z_axis_dec_deg, self.x_axis_ra_deg, self.x_axis_dec_deg]
        if self.quaternion is not None:
            if any(v is not None for v in radec):
                raise ValueError("give either quaternion or the z/x axis RA/Dec, not both")
            norm = sum(c * c for c in self.quaternion) ** 0.5
            if not abs(norm - 1.0) <= 1e-6:  # written so that a NaN norm fails too
                raise ValueError(f"quaternion {self.quaternion} has norm {norm:.6g}; it must be 1")
        elif any(v is None for v in radec):
            raise ValueError(
                "give quaternion: [w, x, y, z], or all of z_axis_ra_deg, z_axis_dec_deg, "
                "x_axis_ra_deg, x_axis_dec_deg"
            )
        return self


class FixedAttitude(AxesOrientation):
    model: Literal["fixed"]


class SpinAttitude(Strict):
    model: Literal["spin"]
    spin_axis_ra_deg: float
    spin_axis_dec_deg: float = Field(ge=-90, le=90)
    period_s: float = Field(gt=0)
    initial_phase_deg: float = 0.0
    spin_body_axis: Vector3 = Field(
        default_factory=lambda: [0.0, 0.0, 1.0],
        description="Body-frame axis the body spins about (normalised; default body z)",
    )

    @field_validator("spin_body_axis")
    @classmethod
    def _nonzero_axis(cls, value: Vector3) -> Vector3:
        norm = sum(float(c) * float(c) for c in value) ** 0.5
        if not 0.0 < norm < float("inf"):
            raise ValueError(f"spin_body_axis {list(value)} must be a non-zero vector [x, y, z]")
        return value


class TorqueFreeAttitude(Strict):
    model: Literal["torque_free"]
    inertia_kg_m2: list[float] | list[list[float]] = Field(
        description="Principal moments (3 values) or the full 3x3 tensor in the body frame"
    )
    initial_attitude: AxesOrientation
    angular_velocity_body_rad_s: Vector3
    method: Literal["analytic", "ivp"] = Field(
        default="analytic",
        description="analytic: Jacobi elliptic closed form; ivp: numerical integration (reference)",
    )
    rtol: float = Field(default=1e-12, gt=0, lt=1e-3, description="ivp relative tolerance")
    atol: float = Field(
        default=1e-13, gt=0, lt=1e-3, description="ivp absolute tolerance / analytic angle [rad]"
    )

    @field_validator("inertia_kg_m2")
    @classmethod
    def _shape(cls, value: list[float] | list[list[float]]) -> list[float] | list[list[float]]:
        ok_vector = len(value) == 3 and all(isinstance(v, float | int) for v in value)
        ok_matrix = len(value) == 3 and all(isinstance(r, list) and len(r) == 3 for r in value)
        if not (ok_vector or ok_matrix):
            raise ValueError(f"{value} is neither 3 principal moments nor a 3x3 tensor [kg m^2]")
        return value
