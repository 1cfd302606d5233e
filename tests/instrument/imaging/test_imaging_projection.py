"""The TAN projection against astropy's WCS, and the raster's conservation of light."""

from __future__ import annotations

import numpy as np
import pytest

from speclight.attitude.quaternion import unit_vector_from_radec
from speclight.instrument.imaging.sky_projection import Pointing, frame_wcs, sky_to_pixel
from speclight.instrument.imaging.streak_raster import add_source, splat_bilinear


@pytest.mark.parametrize(
    ("ra", "dec", "pa"), [(10.0, 5.0, 0.0), (250.0, -60.0, 33.0), (0.1, 89.5, 170.0)]
)
def test_projection_matches_astropy_wcs(ra, dec, pa) -> None:
    from astropy.coordinates import SkyCoord

    pointing = Pointing(unit_vector_from_radec(ra, dec), 2.5, pa, 640, 480)
    rng = np.random.default_rng(1)
    off = rng.uniform(-0.4, 0.4, size=(50, 2))  # deg
    cosd = np.cos(np.radians(dec))
    ras, decs = ra + off[:, 0] / max(cosd, 0.05), np.clip(dec + off[:, 1], -89.99, 89.99)
    x, y = sky_to_pixel(unit_vector_from_radec(ras, decs), pointing)
    ax, ay = frame_wcs(pointing).world_to_pixel(SkyCoord(ras, decs, unit="deg", frame="icrs"))
    # float64 trigonometry of two implementations of the same projection
    assert np.max(np.hypot(x - ax, y - ay)) < 1e-6


def test_north_is_up_and_east_left_at_position_angle_zero() -> None:
    pointing = Pointing(unit_vector_from_radec(100.0, 10.0), 1.0, 0.0, 101, 101)
    x, y = sky_to_pixel(
        unit_vector_from_radec([100.0, 100.0 + 1 / 3600], [10.0 + 1 / 3600, 10.0]), pointing
    )
    assert y[0] == pytest.approx(51.0, abs=1e-6) and x[0] == pytest.approx(50.0, abs=1e-6)
    assert x[1] < 50.0  # east to the left


def test_bilinear_splat_keeps_light_and_centroid() -> None:
    rng = np.random.default_rng(2)
    u, v, w = rng.uniform(2, 30, 200), rng.uniform(2, 20, 200), rng.uniform(0, 1, 200)
    grid = splat_bilinear((24, 34), u, v, w)
    y, x = np.indices(grid.shape)
    assert grid.sum() == pytest.approx(w.sum(), rel=1e-12)
    assert (grid * x).sum() / grid.sum() == pytest.approx((w * u).sum() / w.sum(), rel=1e-12)
    assert (grid * y).sum() / grid.sum() == pytest.approx((w * v).sum() / w.sum(), rel=1e-12)


def test_long_diagonal_streak_in_pieces_keeps_light() -> None:
    kernel = np.zeros((9, 9))
    kernel[4, 4] = 1.0  # a delta: every electron lands in the pixel of its point
    image = np.zeros((700, 700))
    x = np.linspace(10.0, 690.0, 5000)
    landed = add_source(image, x, x, np.ones(5000), kernel, 2)
    assert landed == pytest.approx(5000.0, rel=1e-12)
    assert image.sum() == pytest.approx(5000.0, rel=1e-12)
    assert np.triu(image, 3).max() < 1e-12  # nothing far off the diagonal (FFT round-off)
