"""Ground observer on the WGS84 ellipsoid: position, topocentric range/azimuth/elevation.

Positions are *geometric* (instantaneous): the light time from a target at most a few
thousand km away is <= 20 ms, during which a LEO target moves <= 150 m (<= 10" seen from
the site) and the range changes by <= 100 m for range rates up to 5 km/s. Neither the
light time nor the diurnal aberration (0.3") is applied; laser ranging at metre level
must add the light-time iteration itself. Azimuth is measured from geodetic north
through east; elevation above the plane normal to the WGS84 ellipsoid normal.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from skyfield.earthlib import refract
from skyfield.toposlib import wgs84

from speclight.constants import EARTH_ROTATION_RATE_RAD_S
from speclight.errors import InputError
from speclight.orbit.frames import EarthOrientation, TimeLike, earth_orientation


@dataclass(frozen=True)
class Site:
    """An observing site on the WGS84 ellipsoid.

    Attributes
    ----------
    latitude_deg
        Geodetic latitude [deg], -90..90, north positive.
    longitude_deg
        Longitude [deg], east positive.
    altitude_m
        Height above the WGS84 ellipsoid [m].
    """

    latitude_deg: float
    longitude_deg: float
    altitude_m: float = 0.0

    def __post_init__(self) -> None:
        if not -90.0 <= float(self.latitude_deg) <= 90.0:
            raise InputError(
                f"latitude_deg = {self.latitude_deg} must be within -90..90 (geodetic, north +)",
                field="observer.latitude_deg",
            )
        if not -360.0 <= float(self.longitude_deg) <= 360.0:
            raise InputError(
                f"longitude_deg = {self.longitude_deg} must be within -360..360 (east +)",
                field="observer.longitude_deg",
            )
        if not -1.0e4 <= float(self.altitude_m) <= 1.0e5:
            raise InputError(
                f"altitude_m = {self.altitude_m} must be within -10 km..100 km of the "
                "WGS84 ellipsoid (give metres, not km)",
                field="observer.altitude_m",
            )

    @property
    def position_itrs_m(self) -> NDArray[np.float64]:
        """ITRS position [m], shape (3,)."""
        pos = wgs84.latlon(self.latitude_deg, self.longitude_deg, elevation_m=self.altitude_m)
        return np.asarray(pos.itrs_xyz.m, dtype=np.float64)

    @property
    def enu_matrix(self) -> NDArray[np.float64]:
        """Rows: unit east, north, up vectors in ITRS (geodetic), shape (3, 3)."""
        lat, lon = np.radians(self.latitude_deg), np.radians(self.longitude_deg)
        sl, cl, so, co = np.sin(lat), np.cos(lat), np.sin(lon), np.cos(lon)
        return np.array([[-so, co, 0.0], [-sl * co, -sl * so, cl], [cl * co, cl * so, sl]])


def site_position_gcrs_m(
    site: Site, t: TimeLike, orientation: EarthOrientation | None = None
) -> NDArray[np.float64]:
    """Geocentric GCRS position of the site [m], shape (N, 3)."""
    eo = orientation if orientation is not None else earth_orientation(t)
    n = eo.gcrs_to_itrs.shape[0]
    return eo.itrs_to_gcrs(np.broadcast_to(site.position_itrs_m, (n, 3)))


def site_velocity_gcrs_m_s(
    site: Site, t: TimeLike, orientation: EarthOrientation | None = None
) -> NDArray[np.float64]:
    """Velocity of the site in the GCRS [m s-1], shape (N, 3): the Earth's rotation.

    ``omega x r`` with ``omega`` the rotation rate
    (:data:`~speclight.constants.EARTH_ROTATION_RATE_RAD_S`) about the ITRS pole. The rates
    of precession, nutation and polar motion (< 1e-7 of the rotation) are left out.
    """
    eo = orientation if orientation is not None else earth_orientation(t)
    axis_gcrs = eo.gcrs_to_itrs[:, 2, :]  # the ITRS z axis in GCRS components
    r_site = site_position_gcrs_m(site, t, orientation=eo)
    return np.asarray(EARTH_ROTATION_RATE_RAD_S * np.cross(axis_gcrs, r_site), dtype=np.float64)


@dataclass(frozen=True)
class Topocentric:
    """Topocentric coordinates of a target, each of shape (N,).

    Attributes
    ----------
    range_m
        Site-to-target distance [m].
    azimuth_deg
        From north through east [deg], 0..360.
    elevation_deg
        Above the horizon [deg]; refracted (apparent) if requested.
    """

    range_m: NDArray[np.float64]
    azimuth_deg: NDArray[np.float64]
    elevation_deg: NDArray[np.float64]


def topocentric(
    site: Site,
    r_target_gcrs_m: NDArray[np.float64],
    t: TimeLike,
    refraction: bool = False,
    temperature_C: float = 10.0,
    pressure_mbar: float = 1010.0,
    orientation: EarthOrientation | None = None,
) -> Topocentric:
    """Range, azimuth and elevation of a target seen from a site.

    Parameters
    ----------
    site
        Observer.
    r_target_gcrs_m
        (N, 3) geocentric target position [m].
    t
        Epochs (N).
    refraction
        If True, the elevation is the apparent one, raised by atmospheric refraction
        from Bennett's formula scaled for temperature and pressure (Bennett 1982, J.
        Navigation 35, 255, doi:10.1017/S0373463300022037; as in skyfield's
        ``earthlib.refract``); zero below -1 deg.
    temperature_C, pressure_mbar
        Air temperature [degC] and pressure [mbar] at the site, for refraction.
    orientation
        Precomputed Earth orientation for ``t``.

    Returns
    -------
    Topocentric
    """
    eo = orientation if orientation is not None else earth_orientation(t)
    r_itrs = eo.gcrs_to_itrs_vec(np.asarray(r_target_gcrs_m, dtype=np.float64))
    enu = (r_itrs - site.position_itrs_m) @ site.enu_matrix.T
    horiz = np.hypot(enu[:, 0], enu[:, 1])
    rng = np.linalg.norm(enu, axis=1)
    az = np.degrees(np.arctan2(enu[:, 0], enu[:, 1])) % 360.0
    el = np.degrees(np.arctan2(enu[:, 2], horiz))
    if refraction:
        finite = np.isfinite(el)
        el_app = el.copy()
        el_app[finite] = refract(el[finite], temperature_C, pressure_mbar)
        el = el_app
    return Topocentric(range_m=rng, azimuth_deg=az, elevation_deg=el)


def phase_angle_deg(
    r_target: NDArray[np.float64], r_sun: NDArray[np.float64], r_observer: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Angle at the target between the directions to the Sun and to the observer [deg].

    All positions (N, 3) in one frame and unit; 0 deg = full phase (Sun behind observer).
    """
    u = np.asarray(r_sun, dtype=np.float64) - r_target
    v = np.asarray(r_observer, dtype=np.float64) - r_target
    cross = np.linalg.norm(np.cross(u, v), axis=-1)
    dot = np.sum(u * v, axis=-1)
    return np.degrees(np.arctan2(cross, dot))
