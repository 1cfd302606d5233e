"""Scenario models of the operational attitude profiles (nadir, pointing, table), and the
union of every attitude model (the scenario's ``attitude`` section).

The frames are defined in :mod:`speclight.attitude.nadir`, :mod:`speclight.attitude.pointing`
and :mod:`speclight.attitude.table`, and in ``docs/scenario.md``; these models only
validate the scenario's values.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, field_validator, model_validator

from speclight.scenario.sections_geometry import (
    FixedAttitude,
    SpinAttitude,
    Strict,
    TorqueFreeAttitude,
    Vector3,
)

#: Secondary-axis references: what the constraint axis is brought as close as possible to.
Constraint = Literal["orbit_normal", "velocity", "nadir", "geocentre", "sun", "radec"]
#: Two unit vectors closer to parallel than this (|sin angle|) do not fix a rotation.
_PARALLEL_SIN = 1e-9


def _norm(v: list[float]) -> float:
    return float(sum(float(c) * float(c) for c in v) ** 0.5)


def _nonzero(name: str, value: list[float]) -> list[float]:
    if not 0.0 < _norm(value) < float("inf"):
        raise ValueError(f"{name} {list(value)} must be a non-zero body-frame vector [x, y, z]")
    return value


class NadirAttitude(Strict):
    """Body +z to nadir, +x toward the velocity (LVLH) or yaw-steered to the Sun."""

    model: Literal["nadir"]
    nadir_type: Literal["geodetic", "geocentric"] = Field(
        default="geodetic",
        description="geodetic: along minus the WGS84 ellipsoid normal; geocentric: to the "
        "Earth's centre",
    )
    yaw_steering: bool = Field(
        default=False, description="Turn about z to keep the Sun in the body x-z plane"
    )
    yaw_sun_side: Literal["+x", "-x"] = Field(
        default="+x", description="Yaw steering: the body x half-plane that holds the Sun"
    )


class _Constrained(Strict):
    """A pointing axis on a direction, a constraint axis as close as possible to another."""

    pointing_axis_body: Vector3 = Field(
        default_factory=lambda: [0.0, 0.0, 1.0],
        description="Body axis put on the pointing direction (normalised; default +z)",
    )
    constraint_axis_body: Vector3 = Field(
        default_factory=lambda: [1.0, 0.0, 0.0],
        description="Body axis brought as close as possible to the constraint (default +x)",
    )
    constraint: Constraint = Field(
        default="orbit_normal",
        description="orbit_normal (r x v), velocity, nadir (geodetic), geocentre, sun, or "
        "radec (constraint_ra_deg, constraint_dec_deg)",
    )
    constraint_ra_deg: float | None = None
    constraint_dec_deg: float | None = Field(default=None, ge=-90, le=90)

    @field_validator("pointing_axis_body", "constraint_axis_body")
    @classmethod
    def _axis(cls, value: list[float], info: object) -> list[float]:
        return _nonzero(str(getattr(info, "field_name", "axis")), value)

    @model_validator(mode="after")
    def _constraint(self) -> _Constrained:
        a, b = self.pointing_axis_body, self.constraint_axis_body
        cross = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
        if _norm(cross) < _PARALLEL_SIN * _norm(a) * _norm(b):
            raise ValueError(
                f"constraint_axis_body {b} is parallel to pointing_axis_body {a}, so it does not "
                "fix the rotation about it; choose another axis (e.g. [1, 0, 0] with [0, 0, 1])"
            )
        radec = (self.constraint_ra_deg, self.constraint_dec_deg)
        if self.constraint == "radec" and None in radec:
            raise ValueError("constraint: radec needs constraint_ra_deg and constraint_dec_deg")
        if self.constraint != "radec" and radec != (None, None):
            raise ValueError(
                f"constraint_ra_deg/constraint_dec_deg are used only with constraint: radec "
                f"(constraint is {self.constraint!r})"
            )
        return self


class SunPointingAttitude(_Constrained):
    """``pointing_axis_body`` toward the Sun."""

    model: Literal["sun_pointing"]

    @model_validator(mode="after")
    def _not_sun(self) -> SunPointingAttitude:
        if self.constraint == "sun":
            raise ValueError(
                "constraint: sun cannot fix the rotation about the Sun direction; choose "
                "orbit_normal, velocity, nadir, geocentre or radec"
            )
        return self


class InertialPointingAttitude(_Constrained):
    """``pointing_axis_body`` toward a fixed direction in GCRS."""

    model: Literal["inertial_pointing"]
    target_ra_deg: float = Field(description="Right ascension of the pointing direction [deg]")
    target_dec_deg: float = Field(ge=-90, le=90, description="Its declination [deg]")


class TargetPointingAttitude(_Constrained):
    """``pointing_axis_body`` toward a ground site on the WGS84 ellipsoid."""

    model: Literal["target_pointing"]
    site_latitude_deg: float = Field(ge=-90, le=90, description="Geodetic latitude [deg]")
    site_longitude_deg: float = Field(ge=-180, le=360, description="East longitude [deg]")
    site_altitude_m: float = Field(
        default=0.0, ge=-500, le=9000, description="Height above the WGS84 ellipsoid [m]"
    )


class TableAttitude(Strict):
    """Tabulated quaternions (CSV: time_utc, w, x, y, z), interpolated by slerp."""

    model: Literal["table"]
    file: str = Field(
        min_length=1,
        description="CSV of time_utc,w,x,y,z; '# frame: body_to_gcrs' (default) or "
        "'# frame: gcrs_to_body'",
    )


ProfileAttitude = (
    NadirAttitude
    | SunPointingAttitude
    | InertialPointingAttitude
    | TargetPointingAttitude
    | TableAttitude
)
"""The operational profiles: their quaternions need the orbit, the Sun or a table."""

AnyAttitude = FixedAttitude | SpinAttitude | TorqueFreeAttitude | ProfileAttitude
Attitude = Annotated[AnyAttitude, Field(discriminator="model")]
"""The scenario's ``attitude`` section: one model, chosen by ``model``."""
