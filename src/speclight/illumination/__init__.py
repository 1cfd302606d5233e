"""Illumination stage: the light sources that shine on the target (the Sun; lasers later)."""

from speclight.illumination.solar import (
    SOLAR_ANGULAR_RADIUS_RAD,
    solar_irradiance_W_m2_nm,
    solar_table,
)

__all__ = ["SOLAR_ANGULAR_RADIUS_RAD", "solar_irradiance_W_m2_nm", "solar_table"]
