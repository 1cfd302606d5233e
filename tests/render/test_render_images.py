"""Hyperspectral images and depth maps kept for chosen epochs."""

import numpy as np
import pytest

from speclight.render import render_intensity
from speclight.target import Material, Reflectance, cube, sphere


def test_image_sums_to_intensity_and_sphere_depth_is_a_hemisphere(caster_variant):
    radius_m, res_px = 1.5, 64
    m = Material("al", "beckmann", Reflectance.conductor("Al"), roughness=0.3)
    sun = np.array([[0.0, 0.0, 1.0], [0.0, 0.6, 0.8]])
    obs = np.array([[0.0, 0.0, 1.0], [0.8, 0.0, 0.6]])
    wl = np.array([400.0, 600.0, 900.0])
    res = render_intensity(
        sphere(radius_m, m),
        sun,
        obs,
        np.ones((2, 3)),
        wl,
        resolution_px=res_px,
        variant=caster_variant,
        keep_images_for=[1],
    )
    assert list(res.images) == [1]
    img = res.images[1]
    assert img.radiance_W_m2_sr_nm.shape == (res_px, res_px, 3)
    # Intensity = sum of radiance x pixel area (definition of the orthographic render).
    total = img.radiance_W_m2_sr_nm.sum(axis=(0, 1)) * img.pixel_size_m**2
    np.testing.assert_allclose(total, res.intensity_W_sr_nm[1], rtol=1e-12)
    # Depth of a sphere seen along the line of sight: -sqrt(R^2 - r^2) at image radius r
    # (nearer than the centre plane is negative); float32 ray casting: 1e-5 m.
    c = (np.arange(res_px) + 0.5) / res_px * 2 * radius_m - radius_m
    x, y = np.meshgrid(c, -c)
    r2 = x**2 + y**2
    inside = r2 < (radius_m * (1 - 2 / res_px)) ** 2
    np.testing.assert_allclose(img.depth_m[inside], -np.sqrt(radius_m**2 - r2[inside]), atol=1e-4)
    assert np.all(np.isnan(img.depth_m[r2 > radius_m**2 * (1 + 2 / res_px) ** 2]))


def test_image_orientation_puts_body_up_at_the_top():
    # Looking along -x at a cube whose +z face is white and the rest black, lit from +z
    # and from the observer side: the top rows must be bright, the bottom dark.
    white = Material("white", "lambertian", Reflectance.constant(1.0))
    black = Material("black", "lambertian", Reflectance.constant(0.0))
    sun = np.array([[1.0, 0.0, 1.0]]) / np.sqrt(2)
    obs = np.array([[1.0, 0.0, 0.2]]) / np.linalg.norm([1.0, 0.0, 0.2])
    res = render_intensity(
        cube(1.0, {"+z": white, "*": black}),
        sun,
        obs,
        np.ones((1, 1)),
        np.array([500.0]),
        resolution_px=32,
        variant="numpy",
        keep_images_for=[0],
    )
    img = res.images[0]
    rad = img.radiance_W_m2_sr_nm[..., 0]
    assert rad[:16].sum() > 0 and rad[16:].sum() == 0
    assert img.up_body @ np.array([0.0, 0.0, 1.0]) > 0.9
    assert set(np.unique(img.part_index)) <= {-1, 0, 4}


def test_keep_images_index_is_checked():
    m = Material("w", "lambertian", Reflectance.constant(0.5))
    from speclight.errors import InputError

    with pytest.raises(InputError, match="keep_images_for"):
        render_intensity(
            sphere(1.0, m),
            [[0, 0, 1.0]],
            [[0, 0, 1.0]],
            np.ones((1, 1)),
            np.array([500.0]),
            keep_images_for=[3],
            variant="numpy",
        )
