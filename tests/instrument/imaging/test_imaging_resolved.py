"""A resolved target: the kept render laid on the sky (orientation, size, light kept)."""

from __future__ import annotations

import numpy as np
import pytest
from synthetic_track import great_circle_track, synthetic_inputs

from speclight.attitude.quaternion import unit_vector_from_radec
from speclight.instrument.imaging.frame_inputs import KeptImages
from speclight.instrument.imaging.frame_set import make_frames
from speclight.instrument.imaging.sky_projection import east_north
from speclight.scenario.sections_imaging import Imaging

pytest.importorskip("galsim")

SCALE, FWHM = 1.0, 3.0  # arcsec
RANGE_M = 1.0e6


def test_a_long_target_along_east_widens_the_frame_along_x() -> None:
    track = great_circle_track(150.0, 20.0, 0.0, 0.0, 1.0e5)
    east, north = east_north(unit_vector_from_radec(150.0, 20.0))
    # a 40 x 10 px image of a bright rectangle 30 x 6 px, pitch 0.5 m: 15 m x 3 m at 1000 km
    # is 3.09" x 0.62" on the sky, its long side along east
    light = np.zeros((1, 1, 10, 40))
    light[0, 0, 2:8, 5:35] = 1.0
    images = KeptImages(
        time_utc=track.time_utc[4:5],
        light=light,
        pixel_size_m=np.array([0.5]),
        right_icrs=east[None, :],
        up_icrs=north[None, :],
        range_m=np.array([RANGE_M]),
    )
    inputs = synthetic_inputs(track)
    inputs = type(inputs)(inputs.track, inputs.photometry, images, inputs.site, "")
    imaging = Imaging.model_validate(
        {
            "detector": {"width_px": 64, "height_px": 64, "plate_scale_arcsec": SCALE,
                         "read_noise_e": 0, "full_well_e": 1e9, "saturation_adu": 2**31 - 1},
            "exposure_s": 1.0, "frames": 1, "start": "2021-03-10T22:00:04Z",
            "psf": {"seeing": {"profile": "gaussian", "fwhm_arcsec": FWHM}, "diffraction": False},
            "sky": {"model": "none"}, "stars": {"catalogue": "none"}, "noise": False,
            "oversampling": 8,
        }
    )  # fmt: skip
    frame = next(iter(make_frames(inputs, imaging, 1.0)))
    assert frame.meta["image_time_utc"] is not None and frame.meta["resolved"]
    e = frame.exposure.mean_e
    y, x = np.indices(e.shape)
    total = e.sum()
    # the shape keeps the light; the PSF kernel holds KERNEL_ENERGY of it
    assert total == pytest.approx(1.0e5 * frame.meta["psf_kernel_energy"], rel=1e-9)
    cx, cy = (e * x).sum() / total, (e * y).sum() / total
    vx = (e * (x - cx) ** 2).sum() / total
    vy = (e * (y - cy) ** 2).sum() / total
    # second moments add: Gaussian PSF sigma^2 + the pixel's 1/12 + a uniform bar's L^2 / 12
    # (L = 30 px x 0.5 m / 1e6 m in arcsec, and 6 px across), east = -x at position angle 0
    rad = 180.0 / np.pi * 3600.0
    length, width = 15.0 / RANGE_M * rad / SCALE, 3.0 / RANGE_M * rad / SCALE
    sigma2 = (FWHM / 2.3548200450309493 / SCALE) ** 2 + 1.0 / 12.0
    assert vx == pytest.approx(sigma2 + length**2 / 12.0, rel=0.02)
    assert vy == pytest.approx(sigma2 + width**2 / 12.0, rel=0.02)
