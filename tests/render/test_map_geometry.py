"""Reflectivity-map conventions: HEALPix directions, phase angle and roll, interpolation weights."""

import numpy as np
import pytest
from astropy import units as u
from astropy_healpix import HEALPix

from speclight.errors import InputError
from speclight.maps.map_geometry import (
    healpix_directions,
    lonlat_deg,
    map_coordinates,
    nside_for,
    sun_observer,
)
from speclight.maps.map_lookup import phase_angle_weights, roll_weights


@pytest.mark.parametrize(("n", "nside"), [(12, 1), (13, 2), (48, 2), (10_000, 32), (12_288, 32)])
def test_nside_is_the_smallest_power_of_two_covering_n(n, nside):
    assert nside_for(n) == nside


def test_fewer_than_twelve_directions_refused():
    with pytest.raises(InputError, match=r"^directions: directions = "):
        nside_for(11)


def test_directions_are_the_library_pixel_centres_in_ring_order():
    # astropy-healpix, an independent implementation, maps each centre back to its index
    nside = 8
    d = healpix_directions(nside)
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0, atol=1e-12)
    lon, lat = lonlat_deg(d)
    hp = HEALPix(nside=nside, order="ring")
    np.testing.assert_array_equal(hp.lonlat_to_healpix(lon * u.deg, lat * u.deg), np.arange(768))


def test_hand_worked_geometry_at_the_x_axis():
    # p = x: e_lon = z x x = y, e_lat = x x y = z. Phase 90 deg, roll 0: the Sun at 45 deg
    # toward +y, the observer at 45 deg toward -y; roll 90 deg turns the plane to x-z.
    h = np.sqrt(0.5)
    s, o = sun_observer([[1.0, 0, 0]], np.radians(90), 0.0)
    np.testing.assert_allclose(s, [[h, h, 0]], atol=1e-12)
    np.testing.assert_allclose(o, [[h, -h, 0]], atol=1e-12)
    s, o = sun_observer([[1.0, 0, 0]], np.radians(90), np.radians(90))
    np.testing.assert_allclose(s, [[h, 0, h]], atol=1e-12)
    np.testing.assert_allclose(o, [[h, 0, -h]], atol=1e-12)


def test_map_coordinates_invert_sun_observer():
    rng = np.random.default_rng(3)
    p = rng.normal(size=(500, 3))
    p /= np.linalg.norm(p, axis=1)[:, None]
    a = rng.uniform(0.01, 3.0, 500)
    r = rng.uniform(0, 2 * np.pi, 500)
    s, o = sun_observer(p, a, r)
    np.testing.assert_allclose(np.sum(s * o, axis=1), np.cos(a), atol=1e-12)  # phase angle
    p2, a2, r2 = map_coordinates(s, o)
    np.testing.assert_allclose(p2, p, atol=1e-9)
    np.testing.assert_allclose(a2, a, atol=1e-9)
    np.testing.assert_allclose(np.angle(np.exp(1j * (r2 - r))), 0.0, atol=1e-9)


def test_opposite_sun_and_observer_have_no_coordinates():
    p, a, r = map_coordinates([[0, 0, 1.0]], [[0, 0, -1.0]])
    assert np.isnan(a[0]) and np.isnan(r[0]) and np.all(np.isnan(p))


def test_phase_weights_linear_and_clamped():
    stored = np.array([0.0, 30.0, 60.0, 90.0])
    idx, w = phase_angle_weights(stored, np.array([45.0, 0.0, 100.0, 30.0]))
    # 45: halfway 30..60; 0: first; 100: clamped to 90; 30: exactly the stored angle
    value = np.sum(stored[idx] * w, axis=0)
    np.testing.assert_allclose(value, [45.0, 0.0, 90.0, 30.0])
    np.testing.assert_allclose(w.sum(axis=0), 1.0)


def test_roll_weights_are_periodic():
    idx, w = roll_weights(8, np.radians([337.5, 22.5, 360.0]))
    # 337.5 deg: halfway between roll 7 (315) and roll 0 (360 = 0)
    np.testing.assert_array_equal(idx[:, 0], [7, 0])
    np.testing.assert_allclose(w[:, 0], [0.5, 0.5])
    np.testing.assert_array_equal(idx[:, 1], [0, 1])
    np.testing.assert_allclose(w[:, 2], [1.0, 0.0])
