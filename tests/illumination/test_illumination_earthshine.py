"""Earthshine (issue 13 item 6) against closed forms.

* Irradiance on a plate facing the Earth from a point above the subsolar point, for a
  Lambertian Earth of albedo a (radiance a E cos(theta) / pi at polar angle theta from the
  subsolar point): with mu = cos(theta), D the distance from the Earth's centre,
  E_plate = 2 a E R^2 int_{R/D}^{1} mu (D mu - R)(D - R mu) / (R^2 + D^2 - 2 R D mu)^2 dmu
  (the emission and incidence cosines and the distance of each ring; integrated here by
  scipy's quad, independently of the code's cells), and its far-field limit
  (2/3) a E (R/D)^2: a Lambertian sphere at zero phase (Russell 1916).
* The pipeline's Earthshine intensity of a Lambertian sphere equals the sum over the cells of
  the Lambert sphere phase law (2/3) rho r^2 w_k E [sin a_k + (pi - a_k) cos a_k] / pi.
"""

import re

import numpy as np
import pytest
from scipy.integrate import quad

import speclight
from speclight.attitude.quaternion import quat_rotate
from speclight.constants import EARTH_MEAN_RADIUS_M as R
from speclight.illumination.earthshine import earthshine_sources

NADIR = np.array([0.0, 0.0, -1.0])


def _plate(distance_m, samples, albedo=1.0, sun=(0.0, 0.0, 1.0)):
    d, w = earthshine_sources(np.array([[0, 0, distance_m]]), np.array([sun]), albedo, samples)
    return float(np.sum(w[0] * np.clip(d[0] @ NADIR, 0.0, None)))


def _closed_form(distance_m):
    def ring(mu):
        return (
            mu
            * (distance_m * mu - R)
            * (distance_m - R * mu)
            / (R * R + distance_m**2 - 2 * R * distance_m * mu) ** 2
        )

    return 2 * R * R * quad(ring, R / distance_m, 1.0, epsabs=0, epsrel=1e-12)[0]


@pytest.mark.parametrize("altitude_m", [550e3, 20_000e3, 35_786e3])
def test_plate_above_the_subsolar_point(altitude_m):
    got = _plate(R + altitude_m, 4096, albedo=0.3)
    assert got == pytest.approx(0.3 * _closed_form(R + altitude_m), rel=2e-5)


def test_far_field_is_a_lambertian_sphere_at_zero_phase():
    distance = 1e11
    assert _plate(distance, 1024) == pytest.approx((2 / 3) * (R / distance) ** 2, rel=1e-4)


def test_default_cells_are_within_five_percent():
    # the docs say "64 cells: about 3 %"; checked at LEO for a Sun overhead and one low
    for sun in [(0.0, 0.0, 1.0), (1.0, 0.0, 0.2)]:
        sun = tuple(np.array(sun) / np.linalg.norm(sun))
        fine, coarse = _plate(R + 550e3, 4096, sun=sun), _plate(R + 550e3, 64, sun=sun)
        assert abs(coarse / fine - 1) < 0.05


def test_night_and_below_ground():
    d, w = earthshine_sources(
        np.array([[0, 0, R + 500e3], [0, 0, R - 1.0]]), np.array([[0, 0, -1.0]] * 2), 0.3, 64
    )
    assert np.all(w[0] == 0.0)  # the Sun behind the Earth: the whole visible cap is night
    assert np.all(np.isnan(w[1]))
    assert np.allclose(np.linalg.norm(d[0], axis=-1), 1.0)


def test_pipeline_earthshine_of_a_lambertian_sphere():
    radius, rho = 0.5, 0.9
    overrides = {
        "render.resolution_px": 128,
        "time.start": "2020-07-18T01:27:25Z",
        "time.stop": "2020-07-18T01:27:35Z",
        "time.step_s": 5,
        "target": {
            "shape": {"builtin": "sphere", "radius_m": radius},
            "materials": {"body": {"bsdf": "lambertian", "reflectance": rho}},
        },
        "illumination.earthshine": {"albedo": 0.3, "samples": 64},
        "illumination.sun": False,
    }
    result = speclight.simulate("lcs1", overrides)
    ds, geo = result.dataset, result.geometry
    idx = np.flatnonzero(geo.observable)
    assert idx.size == 3
    q = geo.quaternion_body_to_gcrs[idx]
    sun = quat_rotate(q, geo.sun_direction_body[idx])
    obs = quat_rotate(q, geo.observer_direction_body[idx])
    d, w = earthshine_sources(geo.r_target_gcrs_m[idx], sun, 0.3, 64)
    assert np.all((w > 0).sum(axis=1) > 0)  # part of the visible Earth is lit
    a = np.arccos(np.clip(np.einsum("nkc,nc->nk", d, obs), -1, 1))
    phase = (np.sin(a) + (np.pi - a) * np.cos(a)) / np.pi
    expected = (2 / 3) * rho * radius**2 * np.einsum("nk,nk->n", w, phase)[:, None]
    expected = expected * ds["solar_irradiance"].values[idx]
    got = ds["earthshine_intensity"].values[idx]
    # 128 px: the sphere's pixel outline, about 1e-3 (tests/render's Lambert sphere budget)
    np.testing.assert_allclose(got, expected, rtol=3e-3)
    # without the Sun the intensity is the Earthshine alone
    np.testing.assert_allclose(ds["intensity"].values[idx], got, rtol=1e-12)  # float64 rounding


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        ({"albedo": 1.5}, "illumination.earthshine.albedo = 1.5: Input should be less than"),
        ({"samples": 2}, "illumination.earthshine.samples = 2: Input should be greater than"),
        ({"albdo": 0.3}, "did you mean 'albedo'"),
    ],
)
def test_bad_earthshine_fields_name_the_field(value, expected):
    with pytest.raises(speclight.InputError, match=re.escape(expected)):
        speclight.with_overrides(speclight.load("calsphere"), {"illumination.earthshine": value})
