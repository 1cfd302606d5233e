"""Nadir pointing (LVLH) with optional yaw steering.

Frame (body to GCRS, epoch by epoch):

* body +z points to nadir: ``geodetic`` (default), along minus the WGS84 ellipsoid normal
  through the target (toward its geodetic subpoint), or ``geocentric``, toward the Earth's
  centre (``-r / |r|``);
* without yaw steering, body +x is the GCRS velocity made orthogonal to z (the axis that
  completes the right-handed frame closest to the velocity) and ``y = z × x``; for
  geocentric nadir this is the LVLH frame (x along-track, y along minus the orbit normal
  ``-(r × v)``, z to the centre);
* with yaw steering, the bus turns about z so that the Sun stays in the body x-z plane
  (GNSS and many LEO buses: the solar-array axis y stays perpendicular to the Sun, so
  arrays turning about y can face it): ``sun_side = "+x"`` puts the Sun on the +x side
  (``sun_x >= 0``, ``sun_y = 0`` in the body frame; the IGS convention for GPS, Montenbruck
  et al. 2015, "GNSS satellite geometry and attitude models", Adv. Space Res. 56,
  doi:10.1016/j.asr.2015.06.019), ``"-x"`` on the -x side.

Singularity of yaw steering: where the Sun is along ±z (orbit noon and midnight with the
Sun in the orbit plane, |sin(angle)| < 1e-9) the law does not fix the yaw; those epochs use
the velocity-based (LVLH) yaw instead. Near them the ideal law turns the bus about z faster
than real buses can (the "noon/midnight turns" whose rate limits GNSS models add); no yaw-
rate limit is applied here.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from speclight.attitude.pointing import align_constrain
from speclight.attitude.quaternion import FloatArray
from speclight.orbit.shadow import EARTH_EQUATORIAL_RADIUS_M, EARTH_POLAR_RADIUS_M

#: WGS84 semi-major axis [m] and first eccentricity squared (NIMA TR8350.2, 3rd ed., 2000).
WGS84_A_M = EARTH_EQUATORIAL_RADIUS_M
_E2 = 1.0 - (EARTH_POLAR_RADIUS_M / EARTH_EQUATORIAL_RADIUS_M) ** 2
#: Fixed-point iterations of the geodetic latitude: each gains a factor ~e^2 h/(N+h) <
#: 7e-3, so 8 leave < 1e-17 rad.
LATITUDE_ITERATIONS = 8

NadirKind = Literal["geodetic", "geocentric"]
SunSide = Literal["+x", "-x"]


def geodetic_up_itrs(r_itrs_m: ArrayLike) -> FloatArray:
    """Unit WGS84 ellipsoid normals (up) through points given in ITRS, shape (N, 3).

    Geodetic latitude by fixed-point iteration of
    ``tan(phi) = (z + e^2 N(phi) sin(phi)) / p`` (Hofmann-Wellenhof et al., *GNSS*,
    Springer 2008, sec. 10.2.1); the normal is
    ``(cos phi cos lambda, cos phi sin lambda, sin phi)``. NaN rows stay NaN.
    """
    r = np.atleast_2d(np.asarray(r_itrs_m, dtype=np.float64))
    x, y, z = r[:, 0], r[:, 1], r[:, 2]
    p = np.hypot(x, y)
    lon = np.arctan2(y, x)
    lat = np.arctan2(z, p * (1.0 - _E2))
    for _ in range(LATITUDE_ITERATIONS):
        n = WGS84_A_M / np.sqrt(1.0 - _E2 * np.sin(lat) ** 2)
        lat = np.arctan2(z + _E2 * n * np.sin(lat), p)
    cl = np.cos(lat)
    return np.stack((cl * np.cos(lon), cl * np.sin(lon), np.sin(lat)), axis=-1)


def nadir_attitude(
    nadir_gcrs: ArrayLike,
    v_gcrs_m_s: ArrayLike,
    sun_dir_gcrs: ArrayLike | None = None,
    *,
    yaw_steering: bool = False,
    sun_side: SunSide = "+x",
) -> FloatArray:
    """Body-to-GCRS quaternions of a nadir-pointing bus (see the module docstring).

    Parameters
    ----------
    nadir_gcrs
        (N, 3) nadir directions in GCRS (any length): ``-r`` for geocentric nadir, minus
        the ellipsoid normal for geodetic nadir.
    v_gcrs_m_s
        (N, 3) target velocity in GCRS [m/s] (only its direction is used).
    sun_dir_gcrs
        (N, 3) target-to-Sun directions in GCRS (any length); needed for yaw steering.
    yaw_steering
        Turn about z to keep the Sun in the body x-z plane.
    sun_side
        ``"+x"``: Sun on the +x side (``sun_x >= 0``); ``"-x"``: on the -x side.

    Returns
    -------
    numpy.ndarray
        Quaternions (N, 4). NaN rows where the frame is undefined: a NaN input row, or a
        velocity along nadir (no along-track direction) where the yaw comes from it.
    """
    z_body = np.array([0.0, 0.0, 1.0])
    x_body = np.array([1.0, 0.0, 0.0])
    q_lvlh = align_constrain(z_body, nadir_gcrs, x_body, v_gcrs_m_s, field="attitude")
    if not yaw_steering:
        return q_lvlh
    if sun_dir_gcrs is None:
        raise ValueError("yaw steering needs the Sun directions")
    toward_sun = x_body if sun_side == "+x" else -x_body
    q = align_constrain(z_body, nadir_gcrs, toward_sun, sun_dir_gcrs, field="attitude")
    singular = np.isnan(q[:, 0])
    q[singular] = q_lvlh[singular]  # Sun along ±z: the LVLH yaw (see the module docstring)
    return q
