"""Fast Earth-orientation and Sun paths against skyfield's full per-epoch computation,
and the Lagrange interpolator against closed forms.

Reference for the fast path: skyfield 1.55 ``itrs.rotation_at`` / ``TEME.rotation_at``
(IAU 2000A nutation evaluated at every epoch) and ``earth.at(t).observe(sun).apparent()``.
"""

from __future__ import annotations

import math

import numpy as np

from speclight.orbit.frames import as_time, earth_orientation
from speclight.orbit.interpolate import lagrange_interpolate
from speclight.orbit.sun import sun_position_gcrs_m

GEO_RADIUS_M = 42_164_000.0
#: Required agreement of a rotated position at GEO distance (the farthest Earth orbit we
#: treat): 1 mm. Expected ~1e-7 m (interpolation error of nutation on a 1 h grid).
FAST_PATH_TOLERANCE_M = 1e-3
#: Sun position: 1 m at 1 au (7e-12 rad), far below any effect on shadow or illumination.
SUN_TOLERANCE_M = 1.0


def _epochs() -> np.ndarray:
    rng = np.random.default_rng(42)
    start = np.datetime64("2021-03-20T00:00:00", "ns")
    seconds = np.sort(rng.uniform(0.0, 3 * 86400.0, 400))  # 3 days, irregular
    return start + (seconds * 1e9).astype("timedelta64[ns]")


def test_fast_rotations_match_skyfield_full_computation() -> None:
    times = _epochs()
    fast = earth_orientation(times, exact=False)
    exact = earth_orientation(times, exact=True)
    r = np.array([GEO_RADIUS_M, 0.3 * GEO_RADIUS_M, -0.2 * GEO_RADIUS_M])
    r *= GEO_RADIUS_M / np.linalg.norm(r)
    for name in ("gcrs_to_itrs", "gcrs_to_teme"):
        diff = (getattr(fast, name) - getattr(exact, name)) @ r
        assert np.abs(diff).max() < FAST_PATH_TOLERANCE_M, name
    # Orthonormality of the interpolated matrices (a rotation, not a shear).
    m = fast.gcrs_to_itrs
    assert np.abs(m @ np.swapaxes(m, 1, 2) - np.eye(3)).max() < 1e-12


def test_fast_sun_matches_skyfield() -> None:
    times = _epochs()
    diff = sun_position_gcrs_m(times, exact=False) - sun_position_gcrs_m(times, exact=True)
    assert np.abs(diff).max() < SUN_TOLERANCE_M


def test_scalar_and_datetime_inputs() -> None:
    t = as_time(np.datetime64("2021-03-20T00:00:00"))
    assert np.shape(t.whole) == (1,)
    ts_scalar = t.ts.utc(2021, 3, 20)
    assert np.shape(as_time(ts_scalar).whole) == (1,)


def test_lagrange_error_on_circular_motion_matches_theory() -> None:
    # x(t) = R cos(w t): degree-9 Lagrange error bound |R w^10 prod(t - t_k)| / 10!
    # (Cauchy remainder). LCS 1 like orbit: R = 9,170 km, period 145 min, step 240 s.
    radius_m = 9.17e6
    omega = 2 * math.pi / (145.3 * 60.0)
    step = 240.0
    nodes = np.arange(0, 40) * step
    y = radius_m * np.cos(omega * nodes)
    x = np.linspace(nodes[5], nodes[-6], 997)
    yi, ok = lagrange_interpolate(nodes, y, x)
    err = np.abs(yi - radius_m * np.cos(omega * x))
    # The window is centred: nodes -4..+5 steps around a query in (0, step].
    k = np.arange(-4, 6) * step
    probe = np.linspace(0, step, 201)
    prod_max = np.abs(np.prod(probe[:, None] - k[None, :], axis=1)).max()
    bound = radius_m * omega**10 * prod_max / math.factorial(10)
    assert ok.all()
    assert err.max() <= bound
    assert bound < 1e-3  # i.e. sub-millimetre interpolation for such an orbit and step


def test_lagrange_is_exact_at_nodes_and_rejects_outside() -> None:
    nodes = np.array([0.0, 1.0, 3.0, 4.0, 7.0])
    y = nodes**3 - 2 * nodes  # a cubic is reproduced exactly by 5 points
    x = np.array([-0.1, 0.0, 2.5, 7.0, 7.1, np.nan])
    yi, ok = lagrange_interpolate(nodes, y, x)
    assert ok.tolist() == [False, True, True, True, False, False]
    assert np.allclose(yi[ok], x[ok] ** 3 - 2 * x[ok], rtol=0, atol=1e-12)
    assert np.isnan(yi[~ok]).all()
