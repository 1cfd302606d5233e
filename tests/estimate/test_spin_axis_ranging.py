"""Spin axis with ranging returns: a hand-built map where only the range offsets tell the
axis from its reverse, and the worked pieces of the ranging term.

The map is given in closed form (no render): band rates that depend only on the square of
the body z component of the (coaxial) phase vector ``d`` (a body symmetric about its
equatorial plane and about its axis), and a mean range offset ``-0.4 + 0.3 d_z`` m (the
end of the body towards the observer returns first, as for a body longer at +z). For the
spin axis ``a`` and its reverse ``-a``, ``d_z`` only changes sign at every epoch, whatever
the phase (``d_z = los . a``, the spin turns about ``a``): the intensity curves are
identical, the offsets are not.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from speclight.estimate.spin_axis.spin_axis_core import angular_distance_deg, spin_axis_search
from speclight.estimate.spin_axis.spin_axis_lookup import EpochGeometry, spin_frame_map
from speclight.estimate.spin_axis.spin_axis_ranging import (
    RangingTerm,
    offsets_from_channels,
    resolve_weight,
    term_from_offsets,
)
from speclight.maps.map_geometry import healpix_directions
from speclight.maps.map_lookup import MapHeader, ReflectivityMap

RA, DEC = 70.0, 25.0  # the truth; its reverse is RA 250, Dec -25


def _rates(d: np.ndarray) -> np.ndarray:
    return np.stack([1.0 + 3.0 * d[:, 2] ** 2, 2.0 - d[:, 2] ** 2], axis=-1)


def _offset_m(d: np.ndarray) -> np.ndarray:
    return -0.4 + 0.3 * d[:, 2]


def _map(values: np.ndarray, dirs: np.ndarray, nside: int) -> ReflectivityMap:
    header = MapHeader(
        Path("synthetic"), nside, np.array([500.0]), ["b0", "b1"], np.zeros(1), np.zeros(1), {}
    )
    return ReflectivityMap(header, dirs, values.astype(np.float32)[:, None, None, :])


def _unit(ra: float, dec: float) -> np.ndarray:
    r, d = np.radians(ra), np.radians(dec)
    return np.array([np.cos(d) * np.cos(r), np.cos(d) * np.sin(r), np.sin(d)])


def test_only_ranging_breaks_the_reversal() -> None:
    nside = 16
    dirs = healpix_directions(nside)
    rates = _rates(dirs)
    bmap = _map(rates, dirs, nside)
    rmap = _map(np.concatenate([rates, rates * _offset_m(dirs)[:, None]], axis=1), dirs, nside)
    # a line of sight sweeping 100 deg in the plane of the truth and the pole (so that the
    # reflection of the axis across that plane is the axis itself)
    a = _unit(RA, DEC)
    e2 = np.cross(np.cross(a, [0.0, 0.0, 1.0]), a)
    e2 /= np.linalg.norm(e2)
    n, period = 120, 50.0
    ang = np.radians(np.linspace(-80.0, 20.0, n))
    los = np.cos(ang)[:, None] * a + np.sin(ang)[:, None] * e2
    t = np.linspace(0.0, 200.0, n)
    dz = los @ a  # the body z component of the phase vector, any phase
    y = _rates(np.stack([np.zeros(n), np.zeros(n), dz], -1))
    offsets = np.repeat(_offset_m(np.stack([np.zeros(n), np.zeros(n), dz], -1))[:, None], 2, 1)
    geo = EpochGeometry(los, los, t, period)
    grid, phases = 10.0, 12
    sfm = spin_frame_map(bmap, None, phases)
    plain = spin_axis_search(bmap, sfm, geo, y, ["b0", "b1"], grid, None, do_refine=False)
    # without ranging the axis and its reverse (RA + 180, -Dec: both grid cells) tie
    i, j = int(np.argmin(abs(plain.ra_deg - 70))), int(np.argmin(abs(plain.dec_deg - 25)))
    i2, j2 = int(np.argmin(abs(plain.ra_deg - 250))), int(np.argmin(abs(plain.dec_deg + 25)))
    assert plain.error[i, j] == pytest.approx(plain.error[i2, j2], rel=0.05, abs=1e-6)
    term = RangingTerm(rmap, spin_frame_map(rmap, None, phases), offsets, 1.0)
    ranged = spin_axis_search(
        bmap, sfm, geo, y, ["b0", "b1"], grid, None, do_refine=True, ranging=term
    )
    assert ranged.ranging_weight == 1.0
    # the best cell is the truth's (within half a diagonal), not its reverse's
    assert angular_distance_deg(ranged.best[0], ranged.best[1], RA, DEC) <= grid / np.sqrt(2)
    assert ranged.error[i2, j2] > ranged.error[i, j] + 0.1  # offsets of opposite sign
    # refinement with the map's own interpolation stays on the truth's side (nside 16: 3.7 deg)
    assert angular_distance_deg(ranged.refined[0], ranged.refined[1], RA, DEC) < 3.7


def test_offsets_and_term_by_hand() -> None:
    # channels [R0, R1, M0, M1] scaled by [2, 1, 1, 4]: offsets M/R = (1*1)/(2*0.5), 4*3/3
    rm = np.array([[0.5, 3.0, 1.0, 3.0]])
    off = offsets_from_channels(rm, np.array([2.0, 1.0, 1.0, 4.0]), 2)
    np.testing.assert_allclose(off, [[1.0, 4.0]])
    assert offsets_from_channels(np.array([[0.0, 1.0, 5.0, 1.0]]), None, 2)[0, 0] == 0.0
    # measured (2 epochs x 1 band) 1 and -1 (mean square 1), one NaN epoch left out:
    # ((1.5 - 1)^2 + (-1 + 1)^2) / (2 x 1) = 0.125
    meas = np.array([[1.0], [-1.0], [np.nan]])
    pred = np.array([[1.5], [-1.0], [7.0]])
    assert float(term_from_offsets(pred, meas)) == pytest.approx(0.125)
    # balanced weight: median intensity term / median ranging term over the candidates
    # where both are finite (the third is left out): 1.5 / 15
    t = RangingTerm(None, None, meas, None)  # type: ignore[arg-type]
    w = resolve_weight(t, np.array([[1.0, 2.0, 3.0]]), np.array([[10.0, 20.0, np.inf]]))
    assert w.weight == pytest.approx(0.1)
