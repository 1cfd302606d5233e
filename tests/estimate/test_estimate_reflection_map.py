"""The reflection-map core: HEALPix pixel lookups and the per-pixel means.

References the code did not produce:

* astropy-healpix itself (the pixel centres it gives map back to their pixels);
* the RING numbering in closed form (Gorski et al. 2005, ApJ 622, 759, doi:10.1086/427976,
  section 4 / eqs. 4-9): north polar cap ring i (1 <= i < nside) holds pixels
  p = 2 i (i - 1) + j, j = 0 .. 4 i - 1, centred at z = 1 - i^2 / (3 nside^2),
  phi = pi / (2 i) (j + 1/2); the equatorial belt ring i (nside <= i <= 3 nside) holds
  p = 2 nside (nside - 1) + 4 nside (i - nside) + j, j = 0 .. 4 nside - 1, at
  z = 4/3 - 2 i / (3 nside), phi = pi / (2 nside) (j + s / 2), s = (i - nside + 1) mod 2;
* a hand-worked case of three epochs in two pixels.
"""

import numpy as np
import pytest
from astropy_healpix import healpix_to_xyz

from speclight.errors import InputError
from speclight.estimate.reflection_maps.reflection_map_core import (
    check_nside,
    pixel_centres_deg,
    pixel_of,
    reflection_map,
)


def _xyz(z: np.ndarray, phi: np.ndarray) -> np.ndarray:
    s = np.sqrt(1.0 - z**2)
    return np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=-1)


@pytest.mark.parametrize("nside", [1, 4, 16, 64])
def test_the_library_pixel_centres_map_to_their_pixels(nside: int) -> None:
    p = np.arange(12 * nside * nside)
    x, y, z = healpix_to_xyz(p, nside, order="ring")
    np.testing.assert_array_equal(pixel_of(np.stack([x, y, z], axis=1), nside), p)
    # lengths do not matter, only directions
    np.testing.assert_array_equal(pixel_of(7.5 * np.stack([x, y, z], axis=1), nside), p)


@pytest.mark.parametrize("nside", [2, 8, 32])
def test_ring_numbering_matches_the_closed_form(nside: int) -> None:
    cap = [
        (2 * i * (i - 1) + j, 1 - i**2 / (3 * nside**2), np.pi / (2 * i) * (j + 0.5))
        for i in range(1, nside)
        for j in range(4 * i)
    ]
    belt = [
        (
            2 * nside * (nside - 1) + 4 * nside * (i - nside) + j,
            4 / 3 - 2 * i / (3 * nside),
            np.pi / (2 * nside) * (j + ((i - nside + 1) % 2) / 2),
        )
        for i in range(nside, 3 * nside + 1)
        for j in range(4 * nside)
    ]
    p, z, phi = (np.array(c) for c in zip(*(cap + belt), strict=True))
    np.testing.assert_array_equal(pixel_of(_xyz(z, phi), nside), p)
    # the south cap mirrors the north: ring 4 nside - i starts at npix - 2 i (i + 1)
    npix = 12 * nside**2
    south = [
        (npix - 2 * i * (i + 1) + j, -(1 - i**2 / (3 * nside**2)), np.pi / (2 * i) * (j + 0.5))
        for i in range(1, nside)
        for j in range(4 * i)
    ]
    if south:
        ps, zs, phis = (np.array(c) for c in zip(*south, strict=True))
        np.testing.assert_array_equal(pixel_of(_xyz(zs, phis), nside), ps)
    # pixel 0 is the first of the four around the north pole (+z, the body's z axis)
    assert pixel_of([[0.01, 0.01, 1.0]], nside)[0] == 0
    assert pixel_of([[0.01, -0.01, -1.0]], nside)[0] == npix - 1


def test_pixel_centres_are_the_closed_form_ones() -> None:
    lon, lat = pixel_centres_deg(4)
    # pixel 0: ring 1, j 0: z = 1 - 1/48, phi = 45 deg
    assert lon[0] == pytest.approx(45.0)
    assert lat[0] == pytest.approx(np.degrees(np.arcsin(1 - 1 / 48)))
    assert lon.size == 192 and np.all((lat > -90) & (lat < 90))


def test_three_epochs_in_two_pixels_give_the_hand_worked_means() -> None:
    nside = 4
    x, y, z = healpix_to_xyz([5, 100], nside, order="ring")
    a = np.array([x[0], y[0], z[0]])
    b = np.array([x[1], y[1], z[1]])
    tilt = np.array([0.01, -0.01, 0.0])  # well inside the pixel (pixels are ~15 deg)
    directions = np.array([a, a + tilt, b, [np.nan] * 3, b])
    values = np.array(
        [[1.0, 10.0], [3.0, np.nan], [5.0, 50.0], [7.0, 70.0], [np.nan, np.nan]]
    )  # the 4th has no direction, the 5th no value: both left out
    m = reflection_map(directions, values, nside)
    np.testing.assert_array_equal(m.pixel, [5, 5, 100, -1, -1])
    assert m.n_samples[5] == 2 and m.n_samples[100] == 1 and m.n_samples.sum() == 3
    np.testing.assert_array_equal(m.n_band[:, 5], [2, 1])
    np.testing.assert_allclose(m.mean[:, 5], [2.0, 10.0])
    np.testing.assert_allclose(m.mean[:, 100], [5.0, 50.0])
    # sample standard deviation of (1, 3): sqrt(((1-2)^2 + (3-2)^2) / 1)
    assert m.std[0, 5] == pytest.approx(np.sqrt(2.0))
    assert np.isnan(m.std[1, 5]) and np.isnan(m.std[0, 100])  # fewer than 2 values
    empty = np.ones(12 * nside**2, bool)
    empty[[5, 100]] = False
    assert np.all(np.isnan(m.mean[:, empty])) and np.all(m.n_samples[empty] == 0)


@pytest.mark.parametrize("bad", [0, 3, 12, -4, 512, True, 1.5, "16"])
def test_bad_nside_is_refused(bad: object) -> None:
    with pytest.raises(InputError, match=r"^nside: nside = "):
        check_nside(bad)  # type: ignore[arg-type]


def test_shapes_must_match() -> None:
    with pytest.raises(InputError, match=r"\(N, 3\)"):
        reflection_map(np.zeros((4, 2)), np.zeros((4, 1)), 4)
    with pytest.raises(InputError, match=r"\(N, B\)"):
        reflection_map(np.ones((4, 3)), np.zeros((3, 1)), 4)
