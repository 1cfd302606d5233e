"""Derivatives of the map interpolation (:mod:`speclight.maps.map_lookup_grad`).

References: astropy-healpix's own ``bilinear_interpolation_weights`` (the weights our
formulas reproduce, polar caps included), the map's own lookup
(:meth:`ReflectivityMap.intensity_1au`, which the values must equal) and central finite
differences of that lookup under rotations of the body (the spin-axis parameters move the
directions by rotations) and under a change of the phase angle.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from astropy import units as u
from astropy_healpix import bilinear_interpolation_weights
from scipy.spatial.transform import Rotation

from speclight.maps.map_geometry import healpix_directions
from speclight.maps.map_lookup import MapHeader, ReflectivityMap
from speclight.maps.map_lookup_grad import healpix_weight_derivatives, intensity_jacobian


def _unit(rng: np.random.Generator, n: int) -> np.ndarray:
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1)[:, None]


def _map(nside: int, angles_deg: list[float], n_rolls: int) -> ReflectivityMap:
    """Smooth positive channels of direction, phase angle and roll."""
    d = healpix_directions(nside)
    a = np.radians(np.asarray(angles_deg))[None, :, None, None]
    r = (2 * np.pi * np.arange(n_rolls) / n_rolls)[None, None, :, None]
    lobes = np.array([[0.6, -0.48, 0.64], [0.0, 0.8, 0.6], [-0.6, 0.0, 0.8]])
    dl = (d @ lobes.T)[:, None, None, :]
    b = np.arange(3)[None, None, None, :]
    v = 1.5 + dl + 0.6 * dl**2 * np.cos(a) + 0.3 * np.sin(r + b) * np.sin(a) * d[:, :1, None, None]
    header = MapHeader(
        Path("synthetic"),
        nside,
        np.array([500.0]),
        ["b0", "b1", "b2"],
        np.asarray(angles_deg, dtype=float),
        np.arange(n_rolls) * 360.0 / n_rolls,
        {},
    )
    return ReflectivityMap(header, d, v.astype(np.float32))


@pytest.mark.parametrize("nside", [1, 2, 8])
def test_weight_formulas_give_astropy_healpix_weights(nside: int) -> None:
    rng = np.random.default_rng(nside)
    p = _unit(rng, 20000)
    p[:50, 2] = np.sign(p[:50, 2]) * 0.9999  # many points in both polar caps
    p /= np.linalg.norm(p, axis=1)[:, None]
    lon, lat = np.arctan2(p[:, 1], p[:, 0]) % (2 * np.pi), np.arcsin(p[:, 2])
    pix, w = bilinear_interpolation_weights(lon * u.rad, lat * u.rad, nside, order="ring")
    mine, d_lon, d_lat = healpix_weight_derivatives(nside, lon, lat, np.asarray(pix))
    np.testing.assert_allclose(mine, w, atol=1e-9)
    # the derivatives against central differences of astropy-healpix's weights, where the
    # step stays within the same 4 pixels
    h = 1e-7
    for d, dlon, dlat in ((d_lon, h, 0.0), (d_lat, 0.0, h)):
        pp, wp = bilinear_interpolation_weights((lon + dlon) * u.rad, (lat + dlat) * u.rad, nside)
        pm, wm = bilinear_interpolation_weights((lon - dlon) * u.rad, (lat - dlat) * u.rad, nside)
        same = np.all((pp == pix) & (pm == pix), axis=0)
        assert same.mean() > 0.99
        fd = (wp - wm)[:, same] / (2 * h)
        np.testing.assert_allclose(d[:, same], fd, rtol=1e-5, atol=1e-5 * np.abs(fd).max())


def test_values_are_the_maps_own_lookup_and_derivatives_its_differences() -> None:
    bmap = _map(8, [20.0, 50.0, 80.0, 110.0], 6)
    rng = np.random.default_rng(7)
    n = 1500
    s, o = _unit(rng, n), _unit(rng, n)
    z = rng.normal(size=(n, 3))
    z -= np.sum(z * o, axis=1)[:, None] * o  # a change of the observer direction alone
    gens = np.eye(3)
    d_s = np.stack([np.cross(g, s) for g in gens] + [np.zeros_like(s)], axis=-1)
    d_o = np.stack([np.cross(g, o) for g in gens] + [z], axis=-1)
    values, jac = intensity_jacobian(bmap, s, o, d_s, d_o)
    np.testing.assert_array_equal(np.isnan(values), np.isnan(bmap.intensity_1au(s, o)))
    np.testing.assert_allclose(values, bmap.intensity_1au(s, o), rtol=1e-12)
    h = 1e-6
    fd = []
    for k in range(4):

        def moved(e: float, k: int = k) -> np.ndarray:
            if k < 3:
                r = Rotation.from_rotvec(gens[k] * e).as_matrix()
                return bmap.intensity_1au(s @ r.T, o @ r.T)
            oo = o + e * z
            return bmap.intensity_1au(s, oo / np.linalg.norm(oo, axis=1)[:, None])

        fd.append((moved(h) - moved(-h)) / (2 * h))
    fd_arr = np.stack(fd, axis=-1)
    ok = np.isfinite(fd_arr) & np.isfinite(jac)
    rel = np.abs(fd_arr - jac)[ok] / (np.abs(fd_arr) + np.abs(jac) + 1e-3)[ok]
    # piecewise smooth: steps that cross a pixel, roll or phase-angle cell boundary (a
    # kink) disagree; they are a fraction ~ step / cell of the points
    assert np.median(rel) < 1e-7
    assert np.mean(rel > 1e-5) < 0.005
