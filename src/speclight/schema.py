"""The output dataset's schema: every variable's dimensions, units and long name, in one place.

``speclight.simulate`` writes its dataset through this module (:func:`variable`,
:func:`coordinate`), and the readers (``speclight.plot``, the coming ``speclight.estimate``)
read names, units and flag bits from it, so that a variable is described once.
Units follow CF / UDUNITS spelling (``W sr-1 nm-1``), except magnitudes: they are
logarithmic and UDUNITS has no unit for them, so they are written with units ``mag`` (the
spelling of the IAU, FITS, VOUnits and astropy, which xarray and plots print on their axes)
and a ``comment`` that names the magnitude system. A CF checker reports ``mag`` as not
recognised by UDUNITS; that is the one CF finding speclight accepts (``units = "1"`` would
pass but label magnitude axes ``[1]``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

T, TW, TB, TXYZ = ("time",), ("time", "wavelength"), ("time", "band"), ("time", "xyz")
TL = ("time", "laser")
IMG = ("image_time", "y", "x")


@dataclass(frozen=True)
class VariableInfo:
    """Dimensions, CF units and long name of one output variable."""

    dims: tuple[str, ...]
    units: str
    long_name: str
    standard_name: str | None = None
    comment: str | None = None


#: The magnitude system of the AB magnitudes (for their ``comment``).
AB_COMMENT = (
    "magnitude (logarithmic): -2.5 log10 of the photon-weighted in-band irradiance "
    "over that of a 3631 Jy flat f_nu source (Oke & Gunn 1983)"
)
#: The magnitude system of the Vega V magnitudes (for their ``comment``).
VEGA_V_COMMENT = (
    "magnitude (logarithmic): the AB magnitude in speclite's bessell-V band minus "
    "0.02, the AB - Vega offset of V (Blanton & Roweis 2007, AJ 133, 734, table 1; V zero "
    "points of different realisations differ by about 0.01-0.02 mag); absent when the "
    "wavelength grid does not cover the V band"
)

#: The reference frame of the Stokes parameters (for their ``comment``).
POLARIZATION_FRAME = (
    "Stokes frame on the sky at the observer (IAU 1974): reference direction celestial "
    "(GCRS) north at the target's position, angles from north through east; the atmosphere "
    "is taken as unpolarising"
)
#: The sense of Stokes V (checked by tests/render/test_render_polarization_vsign.py).
V_SIGN = (
    "V > 0: right-handed in the IAU (IEEE) sense, the electric vector turning "
    "counter-clockwise (north toward east) as seen by the observer facing the target"
)

#: Units of magnitudes (see the module docstring).
MAG = "mag"

V = VariableInfo
VARIABLES: dict[str, VariableInfo] = {
    # geometry (time)
    "range": V(T, "m", "distance from the observer to the target"),
    "azimuth": V(T, "degree", "topocentric azimuth of the target, east of north"),
    "elevation": V(
        T,
        "degree",
        "topocentric elevation of the target above the horizon",
        comment="geometric (no refraction) unless the scenario sets observer.refraction: the "
        "file's own comment says which",
    ),
    "phase_angle": V(
        T, "degree", "angle between the target-to-Sun and target-to-observer directions"
    ),
    "sunlit": V(T, "1", "fraction of the solar disk visible from the target"),
    "sun_direction_body": V(TXYZ, "1", "unit vector from the target to the Sun, body frame"),
    "observer_direction_body": V(
        TXYZ, "1", "unit vector from the target to the observer, body frame"
    ),
    "phase_vector_body": V(
        TXYZ, "1", "unit bisector of the Sun and observer directions, body frame"
    ),
    "target_position_gcrs": V(TXYZ, "m", "geocentric target position, GCRS"),
    "sun_distance": V(T, "au", "distance from the target to the Sun"),
    "attitude_quaternion": V(
        ("time", "wxyz"), "1", "body-to-GCRS rotation quaternion, scalar first (w, x, y, z)"
    ),
    "flags": V(T, "1", "why an epoch is not fully observable (bit mask)"),
    "outside_support_fraction": V(
        T,
        "1",
        "fraction of the reflected sunlight from outside measured BRDF tables' support",
        comment="light that lab-table materials reflect where their table has no samples, "
        "from the analytic model fitted to the table (target.materials.*.extension; "
        "docs/brdf-models.md), over all the sunlight the target reflects (Earthshine not "
        "counted), integrated over the wavelength grid; 0 without lab tables and in path "
        "mode; flag bit outside_measured_support above 0.5",
    ),
    # where to point (speclight.orbit.sky_position)
    "sun_elevation_site": V(
        T,
        "degree",
        "elevation of the Sun's centre above the observer's horizon",
        comment="geometric (no refraction), as the twilight limits are defined: civil -6, "
        "nautical -12, astronomical -18 degree",
    ),
    "ra": V(
        T,
        "degree",
        "topocentric right ascension of the target, astrometric, ICRS",
        comment="light-time corrected (barycentric), no aberration: comparable with star "
        "catalogue (Gaia) positions",
    ),
    "dec": V(T, "degree", "topocentric declination of the target, astrometric, ICRS"),
    "ra_apparent": V(
        T,
        "degree",
        "topocentric apparent right ascension of the target, true equator and equinox of date",
        comment="aberration by the observer's velocity (Earth and site rotation) applied: "
        "where a telescope points",
    ),
    "dec_apparent": V(
        T,
        "degree",
        "topocentric apparent declination of the target, true equator and equinox of date",
    ),
    "angular_rate": V(
        T,
        "degree s-1",
        "angular rate of the target across the sky",
        comment="of the astrometric direction; a streak on a sidereally tracking telescope "
        "is the rate times the exposure",
    ),
    "ra_cos_dec_rate": V(
        T, "degree s-1", "rate of right ascension times cos(declination), ICRS, east positive"
    ),
    "dec_rate": V(T, "degree s-1", "rate of declination, ICRS, north positive"),
    # the observer's site (scalars; also the global attributes observer_*)
    "observer_latitude": V(
        (), "degrees_north", "geodetic latitude of the observer (WGS84)", "latitude"
    ),
    "observer_longitude": V(
        (), "degrees_east", "longitude of the observer, east positive", "longitude"
    ),
    "observer_altitude": V(
        (),
        "m",
        "height of the observer above the WGS84 ellipsoid",
        "height_above_reference_ellipsoid",
    ),
    "min_elevation": V(
        (), "degree", "minimum elevation: epochs below it are flagged below_min_elevation"
    ),
    "max_sun_elevation": V(
        (),
        "degree",
        "highest elevation of the Sun at the site for a dark sky: epochs above it are "
        "flagged daylight",
    ),
    # spectra and bands
    "solar_irradiance": V(
        TW, "W m-2 nm-1", "solar spectral irradiance at the target (before shadowing)"
    ),
    "intensity": V(
        TW,
        "W sr-1 nm-1",
        "radiant intensity of the target toward the observer, above the atmosphere",
    ),
    "earthshine_intensity": V(
        TW,
        "W sr-1 nm-1",
        "the part of intensity from sunlight reflected by the Earth (illumination.earthshine)",
    ),
    "transmission": V(TW, "1", "atmospheric direct-beam transmission along the line of sight"),
    "spectral_flux": V(TW, "W nm-1", "spectral power entering the telescope aperture"),
    "count_rate": V(TB, "s-1", "detected photo-electrons per second in each band"),
    "ab_magnitude": V(
        TB,
        MAG,
        "AB magnitude of the in-band irradiance at the aperture",
        comment=f"{AB_COMMENT}; through the atmosphere",
    ),
    "ab_magnitude_exo": V(
        TB,
        MAG,
        "exo-atmospheric AB magnitude: the in-band irradiance at the aperture without the "
        "atmosphere's transmission",
        comment=f"{AB_COMMENT}; above the atmosphere (transmission 1)",
    ),
    "ab_magnitude_standard": V(
        TB,
        MAG,
        "standard AB magnitude: ab_magnitude_exo moved to a range of 1000 km, "
        "m - 5 log10(range / 1000 km)",
        comment=f"{AB_COMMENT}; above the atmosphere, range-normalised to 1000 km as SSA "
        "catalogues quote it (phase angle not normalised)",
    ),
    "vega_v_magnitude": V(
        T,
        MAG,
        "Vega magnitude in the Bessell V band of the irradiance at the aperture",
        comment=VEGA_V_COMMENT + "; through the atmosphere",
    ),
    "vega_v_magnitude_standard": V(
        T,
        MAG,
        "standard Vega V magnitude: above the atmosphere, range-normalised to 1000 km",
        comment=VEGA_V_COMMENT + "; above the atmosphere, m - 5 log10(range / 1000 km)",
    ),
    # polarisation (render.polarization; docs/polarization.md)
    "intensity_q": V(
        TW,
        "W sr-1 nm-1",
        "Stokes Q of the intensity, above the atmosphere",
        comment=f"{POLARIZATION_FRAME}; Q > 0: polarised along north",
    ),
    "intensity_u": V(
        TW,
        "W sr-1 nm-1",
        "Stokes U of the intensity, above the atmosphere",
        comment=f"{POLARIZATION_FRAME}; U > 0: polarised at position angle 45 degree",
    ),
    "intensity_v": V(
        TW,
        "W sr-1 nm-1",
        "Stokes V of the intensity, above the atmosphere",
        comment=f"{POLARIZATION_FRAME}; {V_SIGN}, 0 in single mode",
    ),
    **{
        f"intensity_{c}_std": V(
            TW,
            "W sr-1 nm-1",
            f"Monte Carlo standard error of intensity_{c} (0 in single mode)",
            comment=POLARIZATION_FRAME,
        )
        for c in "quv"
    },
    "count_rate_q": V(
        TB,
        "s-1",
        "Stokes Q of the count rate: count rate of light polarised along north minus along east",
        comment=POLARIZATION_FRAME,
    ),
    "count_rate_u": V(
        TB,
        "s-1",
        "Stokes U of the count rate: count rate polarised at position angle 45 degree minus "
        "at 135 degree",
        comment=POLARIZATION_FRAME,
    ),
    "count_rate_v": V(
        TB, "s-1", "Stokes V of the count rate", comment=f"{POLARIZATION_FRAME}; {V_SIGN}"
    ),
    "dolp": V(
        TB,
        "1",
        "degree of linear polarisation in each band, sqrt(Q^2 + U^2) / I of the count rates",
    ),
    "aolp": V(
        TB,
        "degree",
        "angle of linear polarisation in each band, in [0, 180), from north through east",
        comment=POLARIZATION_FRAME,
    ),
    "intensity_std": V(
        TW, "W sr-1 nm-1", "Monte Carlo standard error of the intensity (0 in single mode)"
    ),
    "count_rate_measured": V(
        TB, "s-1", "simulated background-subtracted measurement of the count rate (noisy)"
    ),
    "reflectance_factor": V(
        TB,
        "m2 sr-1",
        "band count rate x range^2 over the aperture area x the band-weighted solar photon "
        "irradiance at the aperture (Nussbaum et al. 2022, eq. 5)",
    ),
    "reflectance_factor_material": V(
        ("time", "material", "band"),
        "m2 sr-1",
        "each material's share of reflectance_factor, from rendering the material alone "
        "(render.per_material; sums to reflectance_factor over material)",
    ),
    "material_reflectance": V(
        ("material",),
        "",
        "the material's reflectance spectrum: shipped table name, file stem, number or n,k",
    ),
    "band_response": V(("band", "wavelength"), "1", "relative spectral response of each band"),
    "optics_transmission": V(("wavelength",), "1", "transmission of the telescope optics"),
    "detector_qe": V(("band", "wavelength"), "1", "detector quantum efficiency"),
    # saved images
    "image_radiance": V(
        (*IMG, "wavelength"), "W m-2 sr-1 nm-1", "reflected spectral radiance per pixel"
    ),
    "image_radiance_q": V(
        (*IMG, "wavelength"),
        "W m-2 sr-1 nm-1",
        "Stokes Q of the reflected spectral radiance per pixel (render.polarization, single mode)",
        comment=f"{POLARIZATION_FRAME}; Q > 0: polarised along north",
    ),
    "image_radiance_u": V(
        (*IMG, "wavelength"),
        "W m-2 sr-1 nm-1",
        "Stokes U of the reflected spectral radiance per pixel (render.polarization, single mode)",
        comment=f"{POLARIZATION_FRAME}; U > 0: polarised at position angle 45 degree",
    ),
    "image_depth": V(
        IMG, "m", "distance along the line of sight behind the plane through the target centre"
    ),
    "image_part": V(IMG, "1", "index of the target part seen in each pixel (-1: none)"),
    "image_pixel_size": V(("image_time",), "m", "pixel pitch at the target"),
    "image_right_body": V(
        ("image_time", "xyz"), "1", "body-frame direction of the image's right axis"
    ),
    "image_up_body": V(("image_time", "xyz"), "1", "body-frame direction of the image's up axis"),
    # lasers and ranging
    "laser_range": V(TL, "m", "transmitter-to-target distance"),
    "laser_elevation": V(TL, "degree", "elevation of the target above the transmitter's horizon"),
    "laser_irradiance": V(
        TL, "W m-2", "laser irradiance at the target (mean power, after the uplink)"
    ),
    "laser_intensity": V(
        TW, "W sr-1 nm-1", "radiant intensity of the target toward the observer from lasers"
    ),
    "return_photons_per_pulse": V(
        ("time", "laser", "band"), "1", "detected return photo-electrons per laser pulse"
    ),
    "return_rate": V(TB, "s-1", "detected laser return photo-electrons per second, all lasers"),
    "range_histogram": V(
        ("time", "band", "range_bin"),
        "s-1",
        "detected laser return photo-electrons per second per range bin",
    ),
    "range_offset": V(TB, "m", "mean return range minus range to the centre of mass (one-way)"),
    "laser_reflectance_factor": V(
        TB,
        "m2 sr-1",
        "laser return rate x range^2 over the aperture area x the band-weighted laser photon "
        "irradiance at the aperture, all lasers (Nussbaum et al. 2022, eq. 5)",
    ),
    "laser_reflectance_factor_material": V(
        ("time", "material", "band"),
        "m2 sr-1",
        "each material's share of laser_reflectance_factor, from rendering the material alone "
        "(render.per_material)",
    ),
}

#: Attributes of the coordinates.
COORDINATES: dict[str, dict[str, str]] = {
    "time": {"long_name": "epoch (UTC)", "standard_name": "time"},
    "wavelength": {
        "units": "nm",
        "long_name": "wavelength (bin centre)",
        "standard_name": "radiation_wavelength",
    },
    "band": {"long_name": "photometric band"},
    "image_time": {"long_name": "epochs whose images are saved"},
    "laser": {"long_name": "laser transmitter"},
    "material": {"long_name": "target material (scenario target.materials key)"},
    "range_bin": {
        "units": "m",
        "long_name": "one-way range offset from the centre of mass (bin centre), "
        "negative = in front",
        "bounds": "range_bin_bounds",
    },
}

#: CF boundary variables (no attributes of their own: they take their coordinate's units).
BOUNDS: dict[str, tuple[str, ...]] = {"range_bin_bounds": ("range_bin", "nv")}

# Bits of the ``flags`` variable (CF flag_masks / flag_meanings), of type FLAG_DTYPE.
FLAG_DTYPE = np.uint16
FLAG_ORBIT_FAILED = 1
FLAG_BELOW_MIN_ELEVATION = 2
FLAG_IN_SHADOW = 4
FLAG_PENUMBRA = 8
FLAG_RENDER_FAILED = 16
FLAG_LASER_BELOW_HORIZON = 32
#: The attitude model gives no attitude: an epoch outside an attitude table, or a pointing
#: profile whose two directions are parallel there.
FLAG_ATTITUDE_UNDEFINED = 64
#: The Sun is above ``observer.max_sun_elevation_deg`` at the site: no dark sky.
FLAG_DAYLIGHT = 128
#: More than :data:`OUTSIDE_SUPPORT_FLAG_FRACTION` of the reflected sunlight came from
#: outside measured BRDF tables' support (``outside_support_fraction``).
FLAG_OUTSIDE_SUPPORT = 256
OUTSIDE_SUPPORT_FLAG_FRACTION = 0.5

FLAG_MEANINGS = {
    FLAG_ORBIT_FAILED: "orbit_failed",
    FLAG_BELOW_MIN_ELEVATION: "below_min_elevation",
    FLAG_IN_SHADOW: "in_earth_shadow",
    FLAG_PENUMBRA: "in_penumbra",
    FLAG_RENDER_FAILED: "render_failed",
    FLAG_LASER_BELOW_HORIZON: "laser_below_horizon",
    FLAG_ATTITUDE_UNDEFINED: "attitude_undefined",
    FLAG_DAYLIGHT: "daylight",
    FLAG_OUTSIDE_SUPPORT: "outside_measured_support",
}
#: Epochs with any of these bits have no measurement of the Sun's reflection.
NOT_OBSERVABLE = (
    FLAG_ORBIT_FAILED
    | FLAG_BELOW_MIN_ELEVATION
    | FLAG_IN_SHADOW
    | FLAG_RENDER_FAILED
    | FLAG_ATTITUDE_UNDEFINED
    | FLAG_DAYLIGHT
)


def flag_attributes() -> dict[str, Any]:
    """CF ``flag_masks`` and ``flag_meanings`` of the ``flags`` variable."""
    masks = np.array(sorted(FLAG_MEANINGS), dtype=FLAG_DTYPE)
    return {
        "flag_masks": masks,
        "flag_meanings": " ".join(FLAG_MEANINGS[int(m)] for m in masks),
    }


def attrs(name: str) -> dict[str, str]:
    """CF attributes (units, long name, standard name) of an output variable."""
    info = VARIABLES[name]
    out = {"units": info.units, "long_name": info.long_name}
    if info.standard_name:
        out["standard_name"] = info.standard_name
    if info.comment:
        out["comment"] = info.comment
    return out


def variable(name: str, data: Any, **extra_attrs: Any) -> tuple[tuple[str, ...], Any, dict]:
    """``(dims, data, attrs)`` of an output variable, for ``ds[name] = variable(name, data)``."""
    return VARIABLES[name].dims, data, {**attrs(name), **extra_attrs}


def units(name: str) -> str:
    """CF units of a variable or coordinate (``""`` if it has none)."""
    if name in VARIABLES:
        return VARIABLES[name].units
    return COORDINATES.get(name, {}).get("units", "")


def label(name: str) -> str:
    """An axis label: the long name and the units in brackets."""
    info = VARIABLES[name]
    return f"{info.long_name} [{info.units}]"
