"""Range-resolved laser returns of spheres against closed forms.

Lambertian sphere, laser coaxial with the receiver (zero phase). Let mu = cos(theta) be the
cosine between the surface normal and the line of sight. A Lambertian surface under the
irradiance E has the radiance rho E mu / pi (incidence angle = exit angle at zero phase). The
orthographic image of the sphere is a disk of radius R; the pixel at projected radius
rho_p = R sin(theta) covers the area d(pi rho_p²) = 2 pi R² mu dmu (the cos of the exit angle
is already in this projected area). Each pixel's return is radiance x area, so the return per
unit mu is proportional to mu x mu = mu². The surface point lies R mu in front of the centre,
so the return-weighted mean distance in front of the centre is

    <R mu> = R int_0^1 mu³ dmu / int_0^1 mu² dmu = R (1/4)/(1/3) = 3R/4,

i.e. the range offset (mean return range minus range to the centre) is -3R/4. The total is
I = (rho E/pi) 2 pi R² int_0^1 mu² dmu = 2/3 rho E R² (the Lambertian sphere at zero phase:
Lambert 1760; e.g. Hapke, *Theory of Reflectance and Emittance Spectroscopy*, 2nd ed., 2012,
eq. 6.6 with the Lambert-sphere phase function (sin a + (pi - a) cos a) / pi).

Near-mirror sphere (Beckmann roughness alpha << 1) at zero phase: the return comes from facets
whose normals are within ~alpha of the line of sight, i.e. the glint at the sub-observer point:
with D ~ exp(-tan² theta / alpha²), theta² has the mean alpha², so the offset is
-R <cos theta> = -R (1 - alpha²/2) + O(alpha^4).

Bistatic (laser at phase angle a from the receiver): the intensity follows the Lambert-sphere
phase law I(a) = 2/3 rho E R² (sin a + (pi - a) cos a) / pi (Hapke 2012, as above), which
checks the laser's shadow rays (terminator) and direction handling.
"""

import numpy as np
import pytest

from speclight.render.laser_returns import LaserLight, render_laser_returns
from speclight.target import Material, Reflectance, sphere

WL = np.array([530.0, 531.0, 532.0])
RES = 128
R = 1.3
#: Pixel-centre (midpoint) quadrature over a disk 128 px wide: the measured error of the
#: weighted means and totals is ~1e-4 of R (it scales as the squared pitch, (2/128)² = 2.4e-4);
#: 1e-3 leaves room for the float32 Mitsuba caster.
QUADRATURE_REL = 1e-3


def _render(material: Material, obs: np.ndarray, laser: np.ndarray, variant: str):
    target = sphere(R, {"body": material})
    e = np.ones((len(obs), 1)) * 2.0  # W m-2 nm-1 in the bin at 531 nm
    light = LaserLight(laser, np.array([1]), e)
    rr = render_laser_returns(target, obs, [light], WL, resolution_px=RES, variant=variant)
    intensity = rr.intensity_W_sr_nm(0)[:, 0]
    return rr, intensity, rr.moment_m[0][:, 0] / intensity


def _views() -> np.ndarray:
    v = np.array([[0.0, 0.0, 1.0], [0.3, -0.5, 0.8], [1.0, 1.0, 1.0]])
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def test_lambertian_sphere_coaxial_offset_is_three_quarters_radius(caster_variant):
    rho = 0.6
    obs = _views()
    rr, intensity, offset = _render(
        Material("paint", "lambertian", Reflectance.constant(rho)), obs, obs, caster_variant
    )
    np.testing.assert_allclose(offset, -0.75 * R, rtol=QUADRATURE_REL)
    np.testing.assert_allclose(intensity, 2.0 / 3.0 * rho * 2.0 * R**2, rtol=QUADRATURE_REL)
    # the histogram holds all of the return, inside [-R, 0] (front half of the sphere)
    hist = rr.histogram[0][:, 0]
    np.testing.assert_allclose(hist.sum(axis=1), intensity, rtol=1e-12)
    centres = 0.5 * (rr.bin_edges_m[1:] + rr.bin_edges_m[:-1])
    width = rr.bin_edges_m[1] - rr.bin_edges_m[0]
    assert np.all(hist[:, centres > width] == 0.0)
    assert np.all(hist[:, centres < -R - width] == 0.0)


def test_near_mirror_sphere_offset_is_close_to_radius(caster_variant):
    alpha = 0.05
    obs = _views()
    _, intensity, offset = _render(
        Material("polished", "beckmann", Reflectance.constant(0.9), roughness=alpha),
        obs,
        obs,
        caster_variant,
    )
    # -R (1 - alpha²/2); the neglected O(alpha^4) term is 6e-6 R; the glint is ~8 px wide
    glint_sampling = 2e-5
    np.testing.assert_allclose(offset, -R * (1.0 - alpha**2 / 2.0), atol=glint_sampling * R)
    assert np.all(intensity > 0)


def test_bistatic_lambertian_sphere_follows_the_phase_law(caster_variant):
    rho = 0.5
    obs = np.tile([0.0, 0.0, 1.0], (4, 1))
    a = np.radians([20.0, 60.0, 100.0, 120.0])
    laser = np.stack([np.sin(a), np.zeros_like(a), np.cos(a)], axis=1)
    _, intensity, offset = _render(
        Material("paint", "lambertian", Reflectance.constant(rho)), obs, laser, caster_variant
    )
    law = 2.0 / 3.0 * rho * 2.0 * R**2 * (np.sin(a) + (np.pi - a) * np.cos(a)) / np.pi
    # the terminator is sampled by pixel centres: the lit crescent at 120 deg is R/2 = 32 px
    # wide, one pixel 3 % of it (weighted by cos_i -> 0 at the edge); measured at 120 deg:
    # 1.2 %, 0.67 %, 0.05 % at 64, 128, 256 px
    terminator_sampling = 1e-2
    np.testing.assert_allclose(intensity, law, rtol=terminator_sampling)
    # every return comes from the hemisphere facing the receiver and lit by the laser: the
    # one-way offset -(p.o + p.l)/2 lies in [-R cos(a/2), 0]
    assert np.all(offset < 0) and np.all(offset > -R * np.cos(a / 2))


@pytest.mark.parametrize("shift", [np.array([0.4, 0.0, 0.0])])
def test_offset_is_relative_to_the_centre_of_mass(shift):
    obs = _views()[:1]
    target = sphere(R, {"body": Material("p", "lambertian", Reflectance.constant(0.5))})
    light = LaserLight(obs, np.array([1]), np.ones((1, 1)))
    rr = render_laser_returns(target, obs, [light], WL, resolution_px=RES, com_body_m=shift)
    offset = rr.moment_m[0][0, 0] / rr.intensity_W_sr_nm(0)[0, 0]
    # moving the centre of mass by s moves the offset by +s.o (geometry, exact)
    np.testing.assert_allclose(offset, -0.75 * R + shift @ obs[0], rtol=QUADRATURE_REL)
