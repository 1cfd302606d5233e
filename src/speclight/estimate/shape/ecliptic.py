"""The frame of shape inversion: ecliptic J2000, Julian dates, poles as (lambda, beta).

Light-curve inversion works in the mean ecliptic and equinox of J2000 (DAMIT's frame): the
pole is ``(lambda, beta)`` there. speclight's geometry is in the GCRS, whose axes are those
of the ICRS to within 0.02 arcsec; the ecliptic is its rotation about x by the obliquity.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

F64 = NDArray[np.float64]

#: Obliquity of the ecliptic at J2000 [rad]: 84381.406 arcsec (IAU 2006 precession,
#: Capitaine et al. 2003, A&A 412, 567, eq. 39; the IAU 1976 value 84381.448 arcsec that some
#: tables use differs by 0.04 arcsec, far below the pole's uncertainty).
OBLIQUITY_J2000_RAD = float(np.deg2rad(84381.406 / 3600.0))
#: Julian date of the Unix epoch 1970-01-01T00:00:00 [d].
JD_UNIX_EPOCH = 2440587.5


def gcrs_to_ecliptic(v_gcrs: ArrayLike) -> F64:
    """Rotate (..., 3) vectors from the GCRS (ICRS axes) to ecliptic J2000."""
    v = np.asarray(v_gcrs, dtype=float)
    c, s = np.cos(OBLIQUITY_J2000_RAD), np.sin(OBLIQUITY_J2000_RAD)
    rot = np.array([[1.0, 0.0, 0.0], [0.0, c, s], [0.0, -s, c]])
    return np.asarray(v @ rot.T)


def ecliptic_to_gcrs(v_ecl: ArrayLike) -> F64:
    """Rotate (..., 3) vectors from ecliptic J2000 to the GCRS (ICRS axes)."""
    v = np.asarray(v_ecl, dtype=float)
    c, s = np.cos(OBLIQUITY_J2000_RAD), np.sin(OBLIQUITY_J2000_RAD)
    rot = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    return np.asarray(v @ rot.T)


def pole_vector(lambda_deg: ArrayLike, beta_deg: ArrayLike) -> F64:
    """(..., 3) unit vector of ecliptic longitude ``lambda_deg`` and latitude ``beta_deg``."""
    lam, bet = np.deg2rad(lambda_deg), np.deg2rad(beta_deg)
    return np.stack(
        [np.cos(bet) * np.cos(lam), np.cos(bet) * np.sin(lam), np.sin(bet)], axis=-1
    ).astype(float)


def pole_angles_deg(v: ArrayLike) -> tuple[F64, F64]:
    """Ecliptic longitude in [0, 360) and latitude [deg] of (..., 3) vectors."""
    x = np.asarray(v, dtype=float)
    lam = np.rad2deg(np.arctan2(x[..., 1], x[..., 0])) % 360.0
    bet = np.rad2deg(np.arcsin(np.clip(x[..., 2] / np.linalg.norm(x, axis=-1), -1.0, 1.0)))
    return np.asarray(lam), np.asarray(bet)


def angular_distance_deg(a: ArrayLike, b: ArrayLike) -> F64:
    """Angle between (..., 3) vectors [deg]."""
    x, y = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    cos = np.sum(x * y, axis=-1) / (np.linalg.norm(x, axis=-1) * np.linalg.norm(y, axis=-1))
    return np.asarray(np.rad2deg(np.arccos(np.clip(cos, -1.0, 1.0))))


def julian_date(time_utc: NDArray[np.datetime64]) -> F64:
    """Julian date [d] of UTC ``datetime64`` epochs (UTC days: no leap seconds counted)."""
    unix_s = (np.asarray(time_utc, "datetime64[ns]") - np.datetime64(0, "ns")) / np.timedelta64(
        1, "s"
    )
    return np.asarray(unix_s / 86400.0 + JD_UNIX_EPOCH, dtype=float)
