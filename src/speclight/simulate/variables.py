"""Names, units and long names of the output variables (SPEC section 4), in one place."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class VariableInfo:
    units: str
    long_name: str
    standard_name: str | None = None


VARIABLES: dict[str, VariableInfo] = {
    "range": VariableInfo("m", "distance from the observer to the target"),
    "azimuth": VariableInfo("degree", "topocentric azimuth of the target, east of north"),
    "elevation": VariableInfo("degree", "topocentric elevation of the target above the horizon"),
    "phase_angle": VariableInfo(
        "degree", "angle between the target-to-Sun and target-to-observer directions"
    ),
    "sunlit": VariableInfo("1", "fraction of the solar disk visible from the target"),
    "sun_direction_body": VariableInfo("1", "unit vector from the target to the Sun, body frame"),
    "observer_direction_body": VariableInfo(
        "1", "unit vector from the target to the observer, body frame"
    ),
    "phase_vector_body": VariableInfo(
        "1", "unit bisector of the Sun and observer directions, body frame"
    ),
    "target_position_gcrs": VariableInfo("m", "geocentric target position, GCRS"),
    "sun_distance": VariableInfo("au", "distance from the target to the Sun"),
    "attitude_quaternion": VariableInfo(
        "1", "body-to-GCRS rotation quaternion, scalar first (w, x, y, z)"
    ),
    "flags": VariableInfo("1", "why an epoch is not fully observable (bit mask)"),
    "solar_irradiance": VariableInfo(
        "W m-2 nm-1", "solar spectral irradiance at the target (before shadowing)"
    ),
    "intensity": VariableInfo(
        "W sr-1 nm-1", "radiant intensity of the target toward the observer, above the atmosphere"
    ),
    "transmission": VariableInfo(
        "1", "atmospheric direct-beam transmission along the line of sight"
    ),
    "spectral_flux": VariableInfo("W nm-1", "spectral power entering the telescope aperture"),
    "count_rate": VariableInfo("s-1", "detected photo-electrons per second in each band"),
    "ab_magnitude": VariableInfo("mag", "AB magnitude of the in-band irradiance at the aperture"),
    "intensity_std": VariableInfo(
        "W sr-1 nm-1", "Monte Carlo standard error of the intensity (0 in single mode)"
    ),
    "count_rate_measured": VariableInfo(
        "s-1", "simulated background-subtracted measurement of the count rate (noisy)"
    ),
    "band_response": VariableInfo("1", "relative spectral response of each band"),
    "optics_transmission": VariableInfo("1", "transmission of the telescope optics"),
    "detector_qe": VariableInfo("1", "detector quantum efficiency"),
    "image_radiance": VariableInfo("W m-2 sr-1 nm-1", "reflected spectral radiance per pixel"),
    "image_depth": VariableInfo(
        "m", "distance along the line of sight behind the plane through the target centre"
    ),
    "image_part": VariableInfo("1", "index of the target part seen in each pixel (-1: none)"),
}

# Bits of the ``flags`` variable (CF flag_masks / flag_meanings).
FLAG_ORBIT_FAILED = 1
FLAG_BELOW_MIN_ELEVATION = 2
FLAG_IN_SHADOW = 4
FLAG_PENUMBRA = 8
FLAG_RENDER_FAILED = 16
FLAG_LASER_BELOW_HORIZON = 32

FLAG_MEANINGS = {
    FLAG_ORBIT_FAILED: "orbit_failed",
    FLAG_BELOW_MIN_ELEVATION: "below_min_elevation",
    FLAG_IN_SHADOW: "in_earth_shadow",
    FLAG_PENUMBRA: "in_penumbra",
    FLAG_RENDER_FAILED: "render_failed",
    FLAG_LASER_BELOW_HORIZON: "laser_below_horizon",
}


def attrs(name: str) -> dict[str, str]:
    """CF attributes of an output variable."""
    info = VARIABLES[name]
    out = {"units": info.units, "long_name": info.long_name}
    if info.standard_name:
        out["standard_name"] = info.standard_name
    return out
