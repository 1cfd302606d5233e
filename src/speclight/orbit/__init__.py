"""Orbit stage: where the target, the observer and the Sun are, epoch by epoch.

Positions are numpy arrays in metres with the frame in the name (``r_gcrs_m``); times are
skyfield ``Time`` objects or arrays of UTC ``datetime64``. Target sources (TLE, CPF, OEM,
SP3, tabulated ephemerides, observed positions) are listed once, in
:data:`~speclight.orbit.orbit_sources.ORBIT_SOURCES`, with :func:`orbit_trajectory` the front
door. :func:`observation_geometry` bundles what the later stages need (Sun, site, shadow,
range/azimuth/elevation, phase angle, unit vectors).
"""

from speclight.orbit.cpf import Cpf, cpf_position_gcrs_m, read_cpf
from speclight.orbit.cpf_write import format_cpf, write_cpf
from speclight.orbit.ephemeris import Ephemeris, ephemeris_position_gcrs_m, read_ephemeris_csv
from speclight.orbit.frames import EarthOrientation, as_time, earth_orientation
from speclight.orbit.observation import ObservationGeometry, observation_geometry
from speclight.orbit.observer import (
    Site,
    Topocentric,
    phase_angle_deg,
    site_position_gcrs_m,
    topocentric,
)
from speclight.orbit.orbit_sources import ORBIT_SOURCES, OrbitSource, orbit_trajectory
from speclight.orbit.shadow import sunlit_fraction
from speclight.orbit.sun import AU_M, sun_distance_au, sun_position_gcrs_m
from speclight.orbit.timescale import load_ephemeris, load_timescale, time_from_utc
from speclight.orbit.tle import Tle, parse_tle, read_tle_file, read_tles, tle_position_gcrs_m

__all__ = [
    "AU_M",
    "ORBIT_SOURCES",
    "Cpf",
    "EarthOrientation",
    "Ephemeris",
    "ObservationGeometry",
    "OrbitSource",
    "Site",
    "Tle",
    "Topocentric",
    "as_time",
    "cpf_position_gcrs_m",
    "earth_orientation",
    "ephemeris_position_gcrs_m",
    "format_cpf",
    "load_ephemeris",
    "load_timescale",
    "observation_geometry",
    "orbit_trajectory",
    "parse_tle",
    "phase_angle_deg",
    "read_cpf",
    "read_ephemeris_csv",
    "read_tle_file",
    "read_tles",
    "site_position_gcrs_m",
    "sun_distance_au",
    "sun_position_gcrs_m",
    "sunlit_fraction",
    "time_from_utc",
    "tle_position_gcrs_m",
    "topocentric",
    "write_cpf",
]
