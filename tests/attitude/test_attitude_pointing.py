"""Sun, inertial and ground-target pointing against independent constructions.

References: the closest-approach property of a two-axis frame (with body axis b1 held on
t1, the nearest body axis b2 can come to t2 is the difference of the angles
|angle(b1, b2) - angle(t1, t2)|: both b2 and t2 lie on cones about b1 = t1, and the angle
between two points of the cones is smallest in the common meridian plane; Markley &
Crassidis 2014, sec. 5.2); astropy's ``SkyCoord`` for RA/Dec unit vectors; skyfield's WGS84
site positions and SGP4 satellite for the ground-target direction.
"""

from __future__ import annotations

import numpy as np
import pytest
from astropy import units as u
from astropy.coordinates import SkyCoord
from hypothesis import given, settings
from hypothesis import strategies as st
from profile_pass import pass_geometry, skyfield_pass, unit
from skyfield.api import wgs84

from speclight.attitude import quat_to_matrix
from speclight.attitude.pointing import align_constrain
from speclight.attitude.quaternion import PARALLEL_SIN_LIMIT
from speclight.errors import InputError
from speclight.schema import FLAG_ATTITUDE_UNDEFINED

#: Round-off on O(1) direction cosines (a few hundred ulp through the triad products).
ROUNDOFF = 1e-12
#: skyfield and speclight place the site and the SGP4 target to nm: a direction over the
#: >= 1,000 km range agrees to 1e-12; the Earth orientation paths (skyfield's ``itrs`` and
#: speclight's fast path, documented to < 1 um at GEO) add < 1e-12 rad.
SITE_DIRECTION = 1e-11

finite = st.floats(-1.0, 1.0, allow_nan=False)
vectors = st.tuples(finite, finite, finite).filter(lambda v: np.linalg.norm(v) > 0.1)


def _angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    a, b = unit(a), unit(b)
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, axis=-1))


@settings(max_examples=200, deadline=None)
@given(b1=vectors, b2=vectors, t1=vectors, t2=vectors)
def test_align_constrain_is_the_closest_right_handed_rotation(b1, b2, t1, t2):
    b1, b2, t1, t2 = (np.asarray(x, dtype=float) for x in (b1, b2, t1, t2))
    sin_body = np.linalg.norm(np.cross(unit(b1), unit(b2)))
    sin_gcrs = np.linalg.norm(np.cross(unit(t1), unit(t2)))
    if sin_body < PARALLEL_SIN_LIMIT:
        with pytest.raises(InputError, match="parallel"):
            align_constrain(b1, t1, b2, t2)
        return
    q = align_constrain(b1, t1[None], b2, t2[None])
    if sin_gcrs < PARALLEL_SIN_LIMIT:
        assert np.isnan(q).all()
        return
    assert np.isfinite(q).all()
    if min(sin_body, sin_gcrs) < 1e-3:
        return  # well defined, but the closest-approach check below loses digits
    rot = quat_to_matrix(q)[0]
    np.testing.assert_allclose(rot @ rot.T, np.eye(3), atol=ROUNDOFF)
    assert np.linalg.det(rot) == pytest.approx(1.0, abs=ROUNDOFF)
    np.testing.assert_allclose(rot @ unit(b1), unit(t1), atol=ROUNDOFF)
    closest = abs(_angle(b1, b2) - _angle(t1, t2))
    assert _angle(rot @ b2, t2) == pytest.approx(closest, abs=1e-9)


def test_sun_pointing_axis_is_on_the_sun_and_constraint_near_orbit_normal():
    axis, side = [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]
    geo = pass_geometry(
        {"model": "sun_pointing", "pointing_axis_body": axis, "constraint_axis_body": side}
    )
    np.testing.assert_allclose(geo.sun_direction_body @ axis, 1.0, atol=ROUNDOFF)
    sat, t = skyfield_pass(geo)
    g = sat.at(t)
    normal = unit(np.cross(g.position.m.T, g.velocity.m_per_s.T))
    rot = quat_to_matrix(geo.quaternion_body_to_gcrs)
    sun = unit(np.einsum("nij,j->ni", rot, axis))
    # body -z as near the orbit normal as it can come with body y on the Sun
    closest = abs(np.pi / 2 - _angle(sun, normal))
    # (the pipeline's orbit normal comes from its differenced velocity: 6e-8 rad, see
    # test_attitude_nadir.VELOCITY_DIRECTION_RAD)
    np.testing.assert_allclose(_angle(-rot[:, :, 2], normal), closest, atol=6e-8)


def test_inertial_pointing_against_astropy_radec():
    ra, dec = 123.4, -37.5
    geo = pass_geometry(
        {
            "model": "inertial_pointing",
            "target_ra_deg": ra,
            "target_dec_deg": dec,
            "constraint": "radec",
            "constraint_ra_deg": 10.0,
            "constraint_dec_deg": 80.0,
        }
    )
    star = SkyCoord(ra=ra * u.deg, dec=dec * u.deg, frame="gcrs").cartesian.xyz.value
    pole = SkyCoord(ra=10.0 * u.deg, dec=80.0 * u.deg, frame="gcrs").cartesian.xyz.value
    rot = quat_to_matrix(geo.quaternion_body_to_gcrs)
    np.testing.assert_allclose(
        rot[:, :, 2], np.broadcast_to(star, rot[:, :, 2].shape), atol=ROUNDOFF
    )
    # body x in the plane of the star and the pole, on the pole's side
    np.testing.assert_allclose(rot[:, :, 0] @ np.cross(star, pole), 0.0, atol=ROUNDOFF)
    assert np.all(rot[:, :, 0] @ pole > 0.0)


def test_target_pointing_against_skyfield_site():
    site = {"site_latitude_deg": 47.0, "site_longitude_deg": 8.0, "site_altitude_m": 900.0}
    geo = pass_geometry({"model": "target_pointing", "constraint": "velocity", **site})
    sat, t = skyfield_pass(geo)
    place = wgs84.latlon(47.0, 8.0, elevation_m=900.0)
    expected = unit(place.at(t).position.m.T - sat.at(t).position.m.T)
    rot = quat_to_matrix(geo.quaternion_body_to_gcrs)
    np.testing.assert_allclose(rot[:, :, 2], expected, atol=SITE_DIRECTION)


def test_parallel_directions_are_flagged_not_observable():
    # pointing and constraint on the same star: no attitude at any epoch
    same = {"constraint": "radec", "constraint_ra_deg": 50.0, "constraint_dec_deg": 20.0}
    geo = pass_geometry(
        {"model": "inertial_pointing", "target_ra_deg": 50.0, "target_dec_deg": 20.0, **same}
    )
    assert np.all(geo.flags & FLAG_ATTITUDE_UNDEFINED)
    assert not geo.observable.any()
    assert np.isnan(geo.quaternion_body_to_gcrs).all()
