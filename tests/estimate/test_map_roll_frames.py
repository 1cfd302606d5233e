"""The map's cached roll frames (``ReflectivityMap.roll_frames``) against their closed form.

At a direction of longitude ``lon`` and latitude ``lat`` the roll reference axes
(map_geometry's module doc) are the local east ``(-sin lon, cos lon, 0)`` and north
``(-sin lat cos lon, -sin lat sin lon, cos lat)``: the unit vectors of increasing longitude
and latitude on the sphere.
"""

from pathlib import Path

import numpy as np
from astropy_healpix import HEALPix

from speclight.maps.map_lookup import MapHeader, ReflectivityMap


def test_roll_frames_are_east_and_north_of_each_direction():
    hp = HEALPix(4, order="ring")
    lon_q, lat_q = hp.healpix_to_lonlat(np.arange(hp.npix))
    lon, lat = lon_q.rad, lat_q.rad
    d = np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], 1)
    header = MapHeader(Path("t"), 4, np.array([500.0]), ["b"], np.zeros(1), np.zeros(1), {})
    m = ReflectivityMap(header, d, np.zeros((hp.npix, 1, 1, 1), dtype=np.float32))
    e_lon, e_lat = m.roll_frames
    east = np.stack([-np.sin(lon), np.cos(lon), np.zeros_like(lon)], 1)
    north = np.stack([-np.sin(lat) * np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat)], 1)
    # float64 round-off of unit vectors built from trigonometric functions: ~1e-15
    np.testing.assert_allclose(e_lon, east, atol=1e-12)
    np.testing.assert_allclose(e_lat, north, atol=1e-12)
    assert m.roll_frames[0] is e_lon  # made once per loaded map
