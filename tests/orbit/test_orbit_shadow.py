"""Earth shadow (sunlit fraction) against independent shadow geometries.

References (derived here, different code path from speclight.orbit.shadow):
* conical shadow: umbra and penumbra are bounded by the cones tangent to a spherical Sun
  and a spherical Earth (e.g. Montenbruck & Gill 2000, Satellite Orbits, sect. 3.4.2,
  fig. 3.9), built from the Sun-Earth distance and the cone half-angles;
* cylindrical shadow of radius R_earth along the Sun direction;
* the closed-form lens area of two equal circles.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from importlib.resources import files

import numpy as np
import pytest

from speclight.orbit import read_tle_file, sun_position_gcrs_m, sunlit_fraction, tle_position_gcrs_m
from speclight.orbit.shadow import disk_overlap_fraction

TLE_FILE = str(files("speclight") / "data" / "tle" / "calibration_spheres.tle")
R_EARTH_M = 6_378_137.0
R_SUN_M = 695_700_000.0
#: Bisection resolution for event times.
TIME_RESOLUTION_S = 1e-3
#: Penumbra/umbra entry from the fraction and from the tangent cones: the same geometric
#: condition (disk edges touching, c = a + b and c = b - a), so only the bisection
#: resolution separates them.
CONE_AGREEMENT_S = 5 * TIME_RESOLUTION_S
#: At the cylindrical boundary the ray from the target parallel to the shadow axis grazes
#: the Earth, so the Sun's centre lies on the Earth's limb up to the parallax R_E/d_sun
#: (0.9 % of the solar radius, <= 0.6 % in fraction) and the limb's curvature (a/b < 1 %
#: of the Sun's disk for LEO, < 0.3 % in fraction): 0.5 within 0.02.
HALF_FRACTION_TOLERANCE = 0.02


@pytest.fixture(scope="module")
def lcs4():  # type: ignore[no-untyped-def]
    return read_tle_file(TLE_FILE, norad_id=5398)


def _state(tle, seconds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # type: ignore[no-untyped-def]
    t = tle.epoch + (np.atleast_1d(seconds) * 1e9).astype("timedelta64[ns]")
    r, ok = tle_position_gcrs_m(tle, t)
    assert ok.all()
    return r, sun_position_gcrs_m(t)


def _cone_distances(r: np.ndarray, s: np.ndarray) -> dict[str, np.ndarray]:
    """Signed distances (negative = inside) to the penumbra cone, umbra cone, cylinder."""
    d = np.linalg.norm(s, axis=1)
    axis = s / d[:, None]  # unit vector Earth -> Sun
    x = -np.sum(r * axis, axis=1)  # distance behind the Earth along the shadow axis
    perp = np.linalg.norm(r + x[:, None] * axis, axis=1)
    alpha_u = np.arcsin((R_SUN_M - R_EARTH_M) / d)
    alpha_p = np.arcsin((R_SUN_M + R_EARTH_M) / d)
    apex_u = R_EARTH_M * d / (R_SUN_M - R_EARTH_M)  # umbra apex behind the Earth
    apex_p = R_EARTH_M * d / (R_SUN_M + R_EARTH_M)  # penumbra apex on the Sun side
    behind = x > -R_EARTH_M * np.sin(alpha_p)  # beyond the cones' tangent circles
    big = 1e12
    return {
        "penumbra": np.where(behind, perp - (apex_p + x) * np.tan(alpha_p), big),
        "umbra": np.where(behind, perp - (apex_u - x) * np.tan(alpha_u), big),
        "cylinder": np.where(x > 0, perp - R_EARTH_M, big),
    }


def _bisect(pred: Callable[[float], bool], lo: float, hi: float) -> float:
    """Time in [lo, hi] where pred turns from False to True."""
    assert not pred(lo) and pred(hi)
    while hi - lo > TIME_RESOLUTION_S:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if pred(mid) else (mid, hi)
    return 0.5 * (lo + hi)


def test_lens_area_closed_form() -> None:
    # Two unit circles with centres 1 apart: lens area 2*pi/3 - sqrt(3)/2.
    expected = (2 * math.pi / 3 - math.sqrt(3) / 2) / math.pi
    assert disk_overlap_fraction(np.array([1.0]), np.array([1.0]), np.array([1.0]))[0] == (
        pytest.approx(expected, rel=1e-12)
    )
    # Small disk B inside large disk A: covered fraction (b/a)^2.
    got = disk_overlap_fraction(np.array([2.0]), np.array([0.5]), np.array([0.3]))[0]
    assert got == pytest.approx(0.0625, rel=1e-12)


def test_eclipse_entry_matches_cones_and_cylinder(lcs4) -> None:  # type: ignore[no-untyped-def]
    # A coarse scan finds LCS 4's first eclipse after its TLE epoch (2017-08-25).
    scan = np.arange(0.0, 7000.0, 10.0)
    r, s = _state(lcs4, scan)
    f = sunlit_fraction(r, s, earth_model="sphere")
    i_pen = int(np.argmax(f < 1.0))
    i_umb = int(np.argmax(f == 0.0))
    assert 0 < i_pen <= i_umb  # the LEO penumbra lasts ~10 s
    lo, hi = scan[i_pen - 1], scan[i_umb]

    def frac(sec: float) -> float:
        rr, ss = _state(lcs4, np.array([sec]))
        return float(sunlit_fraction(rr, ss, earth_model="sphere")[0])

    def cone(name: str) -> Callable[[float], bool]:
        def inside(sec: float) -> bool:
            rr, ss = _state(lcs4, np.array([sec]))
            return bool(_cone_distances(rr, ss)[name][0] < 0.0)

        return inside

    t_pen_f = _bisect(lambda sec: frac(sec) < 1.0, lo, hi)
    t_umb_f = _bisect(lambda sec: frac(sec) == 0.0, lo, hi)
    t_pen_c = _bisect(cone("penumbra"), lo, hi)
    t_umb_c = _bisect(cone("umbra"), lo, hi)
    t_cyl = _bisect(cone("cylinder"), lo, hi)
    assert abs(t_pen_f - t_pen_c) < CONE_AGREEMENT_S
    assert abs(t_umb_f - t_umb_c) < CONE_AGREEMENT_S
    assert t_pen_c < t_cyl < t_umb_c
    assert frac(t_cyl) == pytest.approx(0.5, abs=HALF_FRACTION_TOLERANCE)

    # Through the penumbra the fraction falls monotonically from 1 to 0.
    sec = np.linspace(t_pen_f - 1.0, t_umb_f + 1.0, 400)
    rr, ss = _state(lcs4, sec)
    fr = sunlit_fraction(rr, ss, earth_model="sphere")
    assert fr[0] == 1.0 and fr[-1] == 0.0
    assert np.all(np.diff(fr) <= 0.0)
    assert np.all((fr >= 0.0) & (fr <= 1.0))


def test_full_sun_and_deep_umbra(lcs4) -> None:  # type: ignore[no-untyped-def]
    scan = np.arange(0.0, 7000.0, 10.0)
    r, s = _state(lcs4, scan)
    f = sunlit_fraction(r, s, earth_model="sphere")
    dist = _cone_distances(r, s)
    outside = dist["penumbra"] > 50e3  # 50 km outside the penumbra cone
    deep = dist["umbra"] < -50e3  # 50 km inside the umbra cone
    assert outside.any() and deep.any()
    assert np.all(f[outside] == 1.0)
    assert np.all(f[deep] == 0.0)


def test_oblate_earth_shadow_is_smaller_near_the_poles(lcs4) -> None:  # type: ignore[no-untyped-def]
    # A polar orbit: with the WGS84 ellipsoid the polar radius is 21 km smaller, so the
    # umbra can only be the same or shorter than with the equatorial-radius sphere.
    scan = np.arange(0.0, 7000.0, 5.0)
    r, s = _state(lcs4, scan)
    sphere = sunlit_fraction(r, s, earth_model="sphere")
    oblate = sunlit_fraction(r, s, earth_model="wgs84")
    assert np.all(oblate >= sphere - 1e-12)
    assert np.sum(oblate == 0.0) < np.sum(sphere == 0.0)
