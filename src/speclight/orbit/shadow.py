"""Earth shadow: the fraction of the solar disk visible from the target (penumbra model).

Seen from the target, the Sun is a disk of angular radius ``a = asin(R_sun / |s - r|)``
and the Earth a disk of angular radius ``b = asin(R_earth / |r|)``, their centres ``c``
apart. The hidden part of the solar disk is the area of overlap of the two circles
(flat-sky formula), and the sunlit fraction is ``1 - overlap / (pi a^2)``. This is the
conical shadow model of Montenbruck & Gill (2000), *Satellite Orbits*, Springer, sect.
3.4.2, doi:10.1007/978-3-642-58351-3. Penumbra starts exactly at ``c = a + b`` and umbra
at ``c = b - a`` (tangent cones). Treating the two disks as flat circles with angular
radii is accurate here because the solar disk is small (0.27 deg): against the exact
overlap of spherical caps (Monte Carlo, Earth disk radius 9 to 64 deg) the fraction
differs by < 3e-4.

The Earth is an oblate WGS84 ellipsoid by default: target and Sun vectors are stretched
along the GCRS z axis by ``a_e / b_e`` so that the ellipsoid becomes a sphere of radius
6378.137 km (an affine map keeps the tangent rays tangent). The GCRS pole differs from the
Earth's pole by precession-nutation (about 0.1 deg in 2020), which changes the effective
radius by < 0.1 km. ``earth_model="sphere"`` uses a sphere of radius 6378.137 km. No atmosphere:
refraction and extinction near the limb, which blur the shadow edge over some tens of km
of grazing height, are neglected.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.typing import NDArray

SUN_RADIUS_M = 695_700_000.0  # IAU 2015 Resolution B3 nominal solar radius
EARTH_EQUATORIAL_RADIUS_M = 6_378_137.0  # WGS84
EARTH_POLAR_RADIUS_M = 6_356_752.314245  # WGS84


def _angle(u: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
    """Angle between rows of u and v [rad], stable for small and large angles."""
    cross = np.linalg.norm(np.cross(u, v), axis=1)
    dot = np.einsum("ij,ij->i", u, v)
    return np.arctan2(cross, dot)


def disk_overlap_fraction(
    a_rad: NDArray[np.float64], b_rad: NDArray[np.float64], c_rad: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Fraction of disk A (radius a) covered by disk B (radius b), centres c apart.

    Flat geometry (Montenbruck & Gill 2000, eq. 3.89 to 3.91).
    """
    a, b, c = np.broadcast_arrays(
        np.asarray(a_rad, float), np.asarray(b_rad, float), np.asarray(c_rad, float)
    )
    out = np.zeros(a.shape)
    full = c <= b - a  # A entirely behind B
    out[full] = 1.0
    inside_a = c <= a - b  # B entirely inside A (annular)
    out[inside_a] = (b[inside_a] / a[inside_a]) ** 2
    part = (c < a + b) & ~full & ~inside_a
    ap, bp, cp = a[part], b[part], c[part]
    x = (cp**2 + ap**2 - bp**2) / (2.0 * cp)
    y = np.sqrt(np.clip(ap**2 - x**2, 0.0, None))
    area = (
        ap**2 * np.arccos(np.clip(x / ap, -1.0, 1.0))
        + bp**2 * np.arccos(np.clip((cp - x) / bp, -1.0, 1.0))
        - cp * y
    )
    out[part] = area / (np.pi * ap**2)
    out[~np.isfinite(a + b + c)] = np.nan
    return np.clip(out, 0.0, 1.0)


def sunlit_fraction(
    r_target_gcrs_m: NDArray[np.float64],
    r_sun_gcrs_m: NDArray[np.float64],
    earth_model: Literal["wgs84", "sphere"] = "wgs84",
) -> NDArray[np.float64]:
    """Fraction of the solar disk visible from the target, 0 (umbra) to 1 (full Sun).

    Parameters
    ----------
    r_target_gcrs_m
        (N, 3) geocentric target position [m].
    r_sun_gcrs_m
        (N, 3) geocentric Sun position [m] (apparent; see :mod:`speclight.orbit.sun`).
    earth_model
        "wgs84" (oblate, default) or "sphere" (radius 6378.137 km).

    Returns
    -------
    ndarray
        (N,) sunlit fraction [1]; NaN where an input row is NaN.
    """
    r = np.array(r_target_gcrs_m, dtype=np.float64, ndmin=2)
    s = np.array(r_sun_gcrs_m, dtype=np.float64, ndmin=2)
    r, s = np.broadcast_arrays(r, s)
    if earth_model == "wgs84":
        stretch = np.array([1.0, 1.0, EARTH_EQUATORIAL_RADIUS_M / EARTH_POLAR_RADIUS_M])
        r, s = r * stretch, s * stretch
    elif earth_model != "sphere":
        raise ValueError(f"earth_model must be 'wgs84' or 'sphere', got {earth_model!r}")
    to_sun = s - r
    d_sun = np.linalg.norm(to_sun, axis=1)
    d_earth = np.linalg.norm(r, axis=1)
    a = np.arcsin(np.clip(SUN_RADIUS_M / d_sun, 0.0, 1.0))
    b = np.arcsin(np.clip(EARTH_EQUATORIAL_RADIUS_M / d_earth, 0.0, 1.0))
    c = _angle(to_sun, -r)
    return 1.0 - disk_overlap_fraction(a, b, c)
