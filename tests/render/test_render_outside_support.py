"""Light from outside a measured table's support: where it is, and how the renders report it.

The support of a lab table (speclight.target.brdf_table) is where it interpolates between
its samples: between its curves at the same distance theta_h from the peak, and not within
one angular step of the peak (narrower than the sampling). Reference: that definition,
applied by hand to three geometries of a flat plate (every pixel sees the same angles), with
the shipped Starlink v1.5 chassis table (incidences 5, 41.4, 60, 75 deg, 1 deg steps).
"""

from __future__ import annotations

import numpy as np
import pytest

import speclight
from speclight import schema
from speclight.render import render_intensity
from speclight.target import Material, Reflectance, plate
from speclight.target.brdf_samples import half_angles_deg

WL = np.array([500.0, 600.0])


def _direction(zenith_deg: float, azimuth_deg: float) -> np.ndarray:
    z, a = np.radians(zenith_deg), np.radians(azimuth_deg)
    return np.array([np.sin(z) * np.cos(a), np.sin(z) * np.sin(a), np.cos(z)])


#: (Sun, observer) on a plate of normal +z, and the expected fraction from outside:
#: the mirror direction (theta_h = 0: the unresolved peak) -> 1; in the plane at incidence
#: 60 deg, exitance 20 deg toward the Sun (theta_h 40, theta_d 20 deg: between the 41.4 deg
#: curve's theta_d 1.4 and the 5 deg curve's 45 deg) -> 0; the Sun 80 deg from the normal and
#: the observer 55 deg, 150 deg round from it (theta_h 33.5, theta_d 63.4 deg: beyond the
#: largest sampled theta_d at that theta_h, 41.5 deg, the 75 deg curve's) -> 1.
CASES = [
    (_direction(30.0, 180.0), _direction(30.0, 0.0), 1.0),
    (_direction(60.0, 180.0), _direction(20.0, 180.0), 0.0),
    (_direction(80.0, 0.0), _direction(55.0, 150.0), 1.0),
]


def test_the_cases_are_where_the_docstring_says():
    th, td = half_angles_deg(np.array([60.0]), np.array([-20.0]))
    assert (th[0], td[0]) == (40.0, 20.0)
    s, o = CASES[2][:2]
    h = (s + o) / np.linalg.norm(s + o)
    assert np.degrees(np.arccos(h[2])) == pytest.approx(33.5, abs=0.1)
    assert np.degrees(np.arccos(s @ h)) == pytest.approx(63.4, abs=0.1)


def test_light_from_outside_the_support_is_reported():
    m = Material("chassis", "measured", Reflectance.constant(1.0),
                 brdf_table="starlink_v1p5_chassis_532nm")  # fmt: skip
    sun = np.array([c[0] for c in CASES])
    obs = np.array([c[1] for c in CASES])
    r = render_intensity(plate(1.0, 1.0, m), sun, obs, np.ones((3, 2)), WL, resolution_px=16)
    assert np.all(r.intensity_W_sr_nm > 0)  # never dark
    fraction = r.outside_support_W_sr_nm / r.intensity_W_sr_nm
    np.testing.assert_array_equal(fraction, np.array([[c[2]] * 2 for c in CASES]))


def test_targets_without_tables_report_nothing_outside():
    m = Material("white", "lambertian", Reflectance.constant(0.5))
    r = render_intensity(plate(1.0, 1.0, m), CASES[0][0][None], CASES[0][1][None],
                         np.ones((1, 2)), WL, resolution_px=16)  # fmt: skip
    assert r.outside_support_W_sr_nm is None


def test_the_output_records_the_fraction_and_its_flag():
    # the built-in Starlink v1.5 pass: forward scattering early on (Sun behind the
    # satellite), light mostly from outside the tables' support; later mostly inside
    ds = speclight.simulate(
        "starlink-v1.5",
        {"render.resolution_px": 24, "spectrum.step_nm": 50, "time.step_s": 60.0},
    ).dataset
    fraction = ds["outside_support_fraction"].values
    flags = ds["flags"].values
    assert ds["flags"].dtype == np.uint16
    lit = np.isfinite(ds["intensity"].values).all(axis=1)
    assert np.all(np.isnan(fraction[~lit])) and np.all((fraction[lit] >= 0) & (fraction[lit] <= 1))
    flagged = (flags & schema.FLAG_OUTSIDE_SUPPORT) != 0
    np.testing.assert_array_equal(flagged, lit & (fraction > schema.OUTSIDE_SUPPORT_FLAG_FRACTION))
    assert flagged.any() and (lit & ~flagged).any()
    assert "outside_measured_support" in ds["flags"].attrs["flag_meanings"].split()


def test_the_shape_inversion_sees_the_extension_too():
    # speclight shape's material law (estimate/shape/scattering.py) sums every channel: at the
    # forward-scattering case, all of the material's light is its extension's
    from speclight.estimate.shape.scattering import scattering_law
    from speclight.target.brdf_table import load_brdf_table

    m = Material("chassis", "measured", Reflectance.constant(1.0),
                 brdf_table="starlink_v1p5_chassis_532nm")  # fmt: skip
    s, o, _ = CASES[2]
    h = (s + o) / np.linalg.norm(s + o)
    law = scattering_law("material", material=m, wavelength_nm=532.0)
    got = law.value(np.array([s[2]]), np.array([o[2]]), np.array([s @ h]))
    table = load_brdf_table("starlink_v1p5_chassis_532nm")
    cos = (np.array([s[2]]), np.array([o[2]]), np.array([h[2]]), np.array([s @ h]))
    assert table.table_part(cos[2], cos[3])[0] == 0.0
    want = s[2] * o[2] * table.extension_part(*cos)  # S = mu0 mu f
    np.testing.assert_allclose(got, want, rtol=1e-12)
