"""Nadir pointing (LVLH) and yaw steering against independent constructions.

References: skyfield's WGS84 ellipsoid (``wgs84.latlon`` places points of known geodetic
latitude; ``wgs84.subpoint_of`` drops the ellipsoid normal from the satellite) and its SGP4
positions and velocities (``EarthSatellite``); the LVLH frame's definition (z to the
Earth's centre, y along minus the orbit normal r × v; Markley & Crassidis 2014, sec. 2.6.4);
the yaw-steering law (Sun in the body x-z plane on the +x side; Montenbruck et al. 2015,
Adv. Space Res. 56, doi:10.1016/j.asr.2015.06.019).
"""

from __future__ import annotations

import numpy as np
from profile_pass import pass_geometry, skyfield_pass, unit
from skyfield.api import wgs84

from speclight.attitude import quat_to_matrix
from speclight.attitude.nadir import geodetic_up_itrs, nadir_attitude
from speclight.schema import FLAG_ATTITUDE_UNDEFINED

#: Round-off on O(1) direction cosines.
ROUNDOFF = 1e-13
#: skyfield's ``subpoint_of`` iterates the geodetic latitude to about 1e-9 rad (measured
#: 1.2e-9 on this pass, with the same ITRS rotation); our normals from points of known
#: latitude agree to 3e-14 (the first test).
SKYFIELD_SUBPOINT_RAD = 5e-9
#: speclight's and skyfield's SGP4 positions agree to nm (same sgp4 library and frame
#: rotations); directions built from them agree to round-off over the 7e6 m radius.
SGP4_DIRECTION = 1e-12
#: The pipeline's velocity is a central difference with h = 0.5 s
#: (``attitude_stage.VELOCITY_STEP``): truncation h^2/6 |d3r/dt3| = h^2 n^3 r / 6 = 4e-4 m/s
#: for this orbit (n = 1.0e-3 rad/s, r = 7.4e6 m), 6e-8 rad of the 7.2 km/s velocity.
VELOCITY_DIRECTION_RAD = 6e-8


def test_geodetic_normal_of_points_of_known_latitude():
    # skyfield computes the forward transformation (lat, lon, h) -> ITRS; our function
    # inverts it: the normal must be (cos lat cos lon, cos lat sin lon, sin lat)
    rng = np.random.default_rng(3)
    lat = rng.uniform(-90.0, 90.0, 100)
    lon = rng.uniform(-180.0, 180.0, 100)
    h = rng.uniform(2e5, 4e7, 100)  # LEO to beyond GEO [m]
    p = np.array(
        [wgs84.latlon(a, b, elevation_m=c).itrs_xyz.m for a, b, c in zip(lat, lon, h, strict=True)]
    )
    la, lo = np.radians(lat), np.radians(lon)
    expected = np.stack((np.cos(la) * np.cos(lo), np.cos(la) * np.sin(lo), np.sin(la)), axis=-1)
    np.testing.assert_allclose(geodetic_up_itrs(p), expected, atol=ROUNDOFF)


def test_nadir_pass_against_skyfield_subpoint_and_velocity():
    geo = pass_geometry({"model": "nadir"})
    sat, t = skyfield_pass(geo)
    g = sat.at(t)
    r, v = g.position.m.T, g.velocity.m_per_s.T
    z = unit(wgs84.subpoint_of(g).at(t).position.m.T - r)  # toward the geodetic subpoint
    x = unit(v - np.einsum("ni,ni->n", v, z)[:, None] * z)  # the velocity made normal to z
    rot = quat_to_matrix(geo.quaternion_body_to_gcrs)
    np.testing.assert_allclose(rot[:, :, 2], z, atol=SKYFIELD_SUBPOINT_RAD)
    np.testing.assert_allclose(rot[:, :, 0], x, atol=SKYFIELD_SUBPOINT_RAD)
    np.testing.assert_allclose(rot[:, :, 1], np.cross(z, x), atol=SKYFIELD_SUBPOINT_RAD)
    # geodetic, not geocentric: at 49 deg N the two differ by ~0.16 deg
    angle = np.degrees(np.arccos(np.einsum("ni,ni->n", unit(-r), z)))
    assert np.all(angle > 0.05)
    assert not np.any(geo.flags & FLAG_ATTITUDE_UNDEFINED)


def test_geocentric_nadir_is_the_lvlh_frame():
    geo = pass_geometry({"model": "nadir", "nadir_type": "geocentric"})
    sat, t = skyfield_pass(geo)
    g = sat.at(t)
    r, v = g.position.m.T, g.velocity.m_per_s.T
    rot = quat_to_matrix(geo.quaternion_body_to_gcrs)
    # LVLH: z = -r/|r|, y = -(r x v)/|r x v|, x = y x z
    np.testing.assert_allclose(rot[:, :, 2], unit(-r), atol=SGP4_DIRECTION)
    np.testing.assert_allclose(rot[:, :, 1], unit(-np.cross(r, v)), atol=VELOCITY_DIRECTION_RAD)
    np.testing.assert_allclose(rot[:, :, 0], np.cross(rot[:, :, 1], rot[:, :, 2]), atol=ROUNDOFF)
    assert np.all(np.einsum("ni,ni->n", rot[:, :, 0], v) > 0.0)


def test_yaw_steering_keeps_the_sun_in_the_body_xz_plane():
    for side, sign in (("+x", 1.0), ("-x", -1.0)):
        geo = pass_geometry({"model": "nadir", "yaw_steering": True, "yaw_sun_side": side})
        sun = geo.sun_direction_body
        np.testing.assert_allclose(sun[:, 1], 0.0, atol=ROUNDOFF)
        assert np.all(sign * sun[:, 0] > 0.0)
        sat, t = skyfield_pass(geo)
        g = sat.at(t)
        z = unit(wgs84.subpoint_of(g).at(t).position.m.T - g.position.m.T)
        rot = quat_to_matrix(geo.quaternion_body_to_gcrs)
        np.testing.assert_allclose(rot[:, :, 2], z, atol=SKYFIELD_SUBPOINT_RAD)


def test_yaw_steering_singularity_falls_back_to_lvlh():
    # Sun exactly along nadir (orbit midnight, Sun in the orbit plane) and exactly along
    # zenith (noon): the law does not fix the yaw, the LVLH frame is used there.
    nadir = np.array([[0.0, 0.0, -1.0], [0.0, 0.0, -1.0], [0.0, 0.0, -1.0]])
    v = np.array([[7.5e3, 0.0, 0.0], [7.5e3, 0.0, 0.0], [7.5e3, 0.0, 0.0]])
    sun = np.array([[0.0, 0.0, -1.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.2]])
    steered = nadir_attitude(nadir, v, sun, yaw_steering=True)
    lvlh = nadir_attitude(nadir, v)
    np.testing.assert_allclose(steered[:2], lvlh[:2], rtol=0, atol=ROUNDOFF)
    rot = quat_to_matrix(steered)
    np.testing.assert_allclose(rot[2, :, 0], [0.0, 1.0, 0.0], atol=ROUNDOFF)  # x to the Sun


def test_velocity_along_nadir_gives_nan_rows():
    q = nadir_attitude(np.array([[0.0, 0.0, -1.0], [1.0, 0.0, 0.0]]), np.array([[0, 0, 5.0]] * 2))
    assert np.isnan(q[0]).all() and np.isfinite(q[1]).all()
