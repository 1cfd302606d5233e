"""Observer geometry and the pipeline's geometry bundle: closed-form cases.

References: local east-north-up geometry on the WGS84 ellipsoid (a target placed along
the ellipsoid normal is at the zenith; along the local north/east horizontal at azimuth
0/90 deg, elevation 0); the phase angle of right-angled and collinear configurations.
"""

from __future__ import annotations

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.orbit import (
    AU_M,
    Site,
    earth_orientation,
    observation_geometry,
    parse_tle,
    phase_angle_deg,
    sun_distance_au,
    tle_position_gcrs_m,
    topocentric,
)

L1 = "1 01361U 65034C   20199.53569372  .00000028  00000-0  25492-2 0  9994"
L2 = "2 01361  32.1395 267.1291 0005455 248.0922 111.8996  9.89297492995906"
SITE = Site(48.7822, 9.1967, 355.0)
#: Round-off of rotations and arctan2 on 1e6 m vectors.
ANGLE_TOLERANCE_DEG = 1e-9
RANGE_TOLERANCE_M = 1e-6


def _times(n: int) -> np.ndarray:
    return np.datetime64("2020-07-17T20:00:00", "ns") + np.arange(n) * np.timedelta64(1, "s")


@pytest.mark.parametrize(
    ("enu", "az", "el"),
    [
        ((0.0, 0.0, 1.0), None, 90.0),
        ((0.0, 1.0, 0.0), 0.0, 0.0),
        ((1.0, 0.0, 0.0), 90.0, 0.0),
        ((-1.0, -1.0, 0.0), 225.0, 0.0),
        ((0.0, -1.0, 1.0), 180.0, 45.0),
    ],
)
def test_local_horizon_cases(enu: tuple[float, float, float], az: float | None, el: float) -> None:
    t = _times(3)
    eo = earth_orientation(t)
    direction = np.array(enu) / np.linalg.norm(enu)
    r_itrs = SITE.position_itrs_m + 1.0e6 * direction @ SITE.enu_matrix
    r_gcrs = eo.itrs_to_gcrs(np.broadcast_to(r_itrs, (3, 3)))
    topo = topocentric(SITE, r_gcrs, t, orientation=eo)
    assert np.allclose(topo.range_m, 1.0e6, rtol=0, atol=RANGE_TOLERANCE_M)
    assert np.allclose(topo.elevation_deg, el, rtol=0, atol=ANGLE_TOLERANCE_DEG)
    if az is not None:
        assert np.allclose(topo.azimuth_deg, az, rtol=0, atol=ANGLE_TOLERANCE_DEG)


def test_site_position_and_normal_closed_form() -> None:
    # WGS84 geodetic -> geocentric (e.g. Hofmann-Wellenhof et al., GNSS, eq. 10.2):
    # N = a / sqrt(1 - e2 sin^2 phi), x = (N + h) cos phi cos lam, ..., z = (N (1 - e2) + h)
    # sin phi; the ellipsoid's gradient at the foot point is the local "up".
    a, f = 6378137.0, 1 / 298.257223563
    e2 = f * (2 - f)
    phi, lam, h = np.radians(48.7822), np.radians(9.1967), 355.0
    n = a / np.sqrt(1 - e2 * np.sin(phi) ** 2)
    ref = np.array(
        [
            (n + h) * np.cos(phi) * np.cos(lam),
            (n + h) * np.cos(phi) * np.sin(lam),
            (n * (1 - e2) + h) * np.sin(phi),
        ]
    )
    assert np.allclose(SITE.position_itrs_m, ref, rtol=0, atol=1e-6)
    up = SITE.enu_matrix[2]
    foot = SITE.position_itrs_m - h * up
    grad = foot / np.array([a * a, a * a, (a * (1 - f)) ** 2])
    assert np.allclose(grad / np.linalg.norm(grad), up, rtol=0, atol=1e-12)


def test_phase_angle_closed_forms() -> None:
    target = np.zeros((3, 3))
    sun = np.array([[1.0, 0, 0], [1.0, 0, 0], [1.0, 0, 0]])
    obs = np.array([[0.0, 2.0, 0], [3.0, 0, 0], [-1.0, 0, 0]])
    assert np.allclose(phase_angle_deg(target, sun, obs), [90.0, 0.0, 180.0], atol=1e-12)


def test_site_rejects_bad_coordinates() -> None:
    with pytest.raises(InputError, match="latitude_deg = 95"):
        Site(95.0, 0.0, 0.0)
    with pytest.raises(InputError, match="not km"):
        Site(45.0, 0.0, 355e3)


def test_observation_geometry_bundle() -> None:
    t = _times(500)
    r, _ = tle_position_gcrs_m(parse_tle(f"{L1}\n{L2}"), t)
    r[7] = np.nan  # a failed epoch stays a NaN row, the others are unaffected
    g = observation_geometry(t, r, SITE)
    for key in (
        "r_sun_gcrs_m",
        "r_site_gcrs_m",
        "sun_direction_gcrs",
        "observer_direction_gcrs",
    ):
        assert g[key].shape == (500, 3)
    for key in (
        "sun_distance_m",
        "sunlit_fraction",
        "range_m",
        "azimuth_deg",
        "elevation_deg",
        "phase_angle_deg",
    ):
        assert g[key].shape == (500,)
        assert np.isnan(g[key][7]) and np.isfinite(np.delete(g[key], 7)).all()
    good = np.isfinite(g["range_m"])
    for key in ("sun_direction_gcrs", "observer_direction_gcrs"):
        assert np.allclose(np.linalg.norm(g[key][good], axis=1), 1.0, atol=1e-12)
    # The phase angle is the angle between the two unit vectors.
    cos = np.sum(g["sun_direction_gcrs"] * g["observer_direction_gcrs"], axis=1)
    assert np.allclose(np.degrees(np.arccos(cos[good])), g["phase_angle_deg"][good], atol=1e-6)
    # The target-Sun distance differs from the Earth-Sun distance by at most |r|.
    d_earth = sun_distance_au(t) * AU_M
    assert np.all(
        np.abs(g["sun_distance_m"][good] - d_earth[good]) <= np.linalg.norm(r[good], axis=1)
    )
    # A rotation keeps the site's geocentric distance.
    r_site = np.linalg.norm(SITE.position_itrs_m)
    assert np.allclose(np.linalg.norm(g["r_site_gcrs_m"], axis=1), r_site, rtol=0, atol=1e-6)
