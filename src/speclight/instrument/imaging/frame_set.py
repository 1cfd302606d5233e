"""All frames of a run: the exposures planned from ``instrument.imaging``, one per band.

:func:`make_frames` plans the exposures (``start``, then every ``cadence_s`` while an
exposure fits inside the dataset's epochs and the target is above the horizon), draws the
PSF of each band once, finds the sky's brightness and the catalogue's stars of each frame,
and records every (exposure, band) with :func:`~speclight.instrument.imaging.exposure.expose`.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.signal import fftconvolve

from speclight.errors import InputError, did_you_mean
from speclight.instrument.imaging.detector_readout import Readout
from speclight.instrument.imaging.exposure import Camera, Exposure, FieldStars, expose
from speclight.instrument.imaging.frame_inputs import FrameInputs
from speclight.instrument.imaging.psf import PsfSpec, fwhm_arcsec, psf_kernel
from speclight.instrument.imaging.resolved_target import RESOLVED_FRACTION, target_shape
from speclight.instrument.imaging.sky_projection import Pointing
from speclight.instrument.imaging.target_path import directions_at, values_at
from speclight.instrument.magnitudes import V_AB_MINUS_VEGA
from speclight.instrument.noise import sky_count_rate_per_s
from speclight.scenario.sections_imaging import MAX_FRAMES, Imaging

F64 = NDArray[np.float64]

#: J2000.0 as UTC (the 64 s of TT - UTC move a star by less than 1e-4 mas at 10"/yr).
J2000_UTC = np.datetime64("2000-01-01T12:00:00", "ns")
#: Days of a Julian year.
JULIAN_YEAR_DAYS = 365.25


@dataclass
class Frame:
    """One recorded frame with what describes it.

    Attributes
    ----------
    index
        Exposure number (0-based).
    band
        Band name.
    start_utc, mid_utc
        Start and middle of the exposure.
    exposure_s
        Exposure time [s].
    exposure
        Pixels, pointing and truth.
    meta
        Per-frame values for the header and the truth table (sky, PSF, resolved...).
    """

    index: int
    band: str
    start_utc: np.datetime64
    mid_utc: np.datetime64
    exposure_s: float
    exposure: Exposure
    meta: dict[str, Any]


def plan_starts(
    inputs: FrameInputs, imaging: Imaging, exposure_s: float
) -> tuple[list[np.datetime64], int]:
    """Exposure starts, and how many were skipped (target below the horizon or no
    geometry)."""
    track = inputs.track
    cadence = imaging.cadence_s or exposure_s
    first = (
        np.datetime64(imaging.start.replace(tzinfo=None), "ns")
        if imaging.start is not None
        else track.time_utc[0]
    )
    last = track.time_utc[-1]
    step = np.timedelta64(round(cadence * 1e9), "ns")
    length = np.timedelta64(round(exposure_s * 1e9), "ns")
    if first < track.time_utc[0] or first + length > last:
        raise InputError(
            f"the first exposure {first} + {exposure_s:g} s is outside the dataset's epochs "
            f"{track.time_utc[0]} .. {last}",
            field="instrument.imaging.start",
        )
    fit = int((last - length - first) // step) + 1
    if imaging.frames is not None and imaging.frames > fit:
        raise InputError(
            f"frames = {imaging.frames}, but {fit} exposures of {exposure_s:g} s every "
            f"{cadence:g} s fit in the dataset's epochs; lower frames or cadence_s",
            field="instrument.imaging.frames",
        )
    count = imaging.frames if imaging.frames is not None else fit
    if count > MAX_FRAMES:
        raise InputError(
            f"{count} exposures fit in the window; at most {MAX_FRAMES} are written: give "
            "frames or a longer cadence_s",
            field="instrument.imaging.frames",
        )
    starts, skipped = [], 0
    finite = np.isfinite(track.ra_deg) & np.isfinite(track.dec_deg)
    for k in range(count):
        t0 = first + k * step
        bracket = slice(  # the epochs around the exposure
            max(int(np.searchsorted(track.time_utc, t0, side="right")) - 1, 0),
            int(np.searchsorted(track.time_utc, t0 + length, side="left")) + 1,
        )
        if not np.all(finite[bracket]) or np.any(track.elevation_deg[bracket] < 0):
            skipped += 1
            continue
        starts.append(t0)
    return starts, skipped


def _band_indices(inputs: FrameInputs, imaging: Imaging) -> list[int]:
    names = inputs.photometry.band_names
    if not names:
        raise InputError("the dataset has no bands: frames need instrument.bands")
    wanted = imaging.bands or list(names)
    out = []
    for name in wanted:
        if name not in names:
            raise InputError(
                f"band '{name}' is not among the dataset's bands ({', '.join(names)})"
                + did_you_mean(name, names),
                field="instrument.imaging.bands",
            )
        out.append(names.index(name))
    return out


def psf_spec(inputs: FrameInputs, imaging: Imaging) -> PsfSpec:
    """The PSF's parts from the imaging section and the telescope."""
    p = imaging.psf
    return PsfSpec(
        seeing_profile=p.seeing.profile if p.seeing is not None else None,
        seeing_fwhm_arcsec=p.seeing.fwhm_arcsec if p.seeing is not None else 0.0,
        moffat_beta=p.seeing.moffat_beta if p.seeing is not None else 4.765,
        diffraction=p.diffraction,
        aperture_diameter_m=inputs.photometry.aperture_diameter_m,
        obstruction_diameter_m=inputs.photometry.obstruction_diameter_m,
        defocus_waves=p.defocus_waves,
        jitter_rms_arcsec=p.jitter_rms_arcsec,
    )


def _sky_v(inputs: FrameInputs, imaging: Imaging, mids: NDArray[np.datetime64]) -> F64:
    """V surface brightness of the sky at each frame [mag arcsec-2] (NaN: no sky)."""
    sky = imaging.sky
    if sky.model == "none":
        return np.full(mids.size, np.nan)
    if sky.model == "fixed":
        return np.full(mids.size, float(sky.v_mag_arcsec2))  # type: ignore[arg-type]
    from speclight.attitude.quaternion import radec_from_unit_vector
    from speclight.instrument.imaging.sky_brightness import sky_conditions, sky_v_mag_arcsec2

    track = inputs.track
    ra, dec = radec_from_unit_vector(directions_at(track, mids))
    sun = (
        values_at(track, track.sun_elevation_deg, mids)
        if track.sun_elevation_deg is not None
        else None
    )
    conditions = sky_conditions(
        mids, *inputs.site, ra, dec, values_at(track, track.elevation_deg, mids), sun
    )
    return sky_v_mag_arcsec2(
        conditions, sky.dark_zenith_v_mag_arcsec2, sky.extinction_v_mag_per_airmass
    )


def _field_stars(
    inputs: FrameInputs,
    imaging: Imaging,
    pointing: Pointing,
    mid: np.datetime64,
    reach_deg: float,
    bands: list[int],
) -> dict[int, FieldStars] | None:
    """Stars near the field with their rates in each band."""
    if imaging.stars.catalogue == "none":
        return None
    from speclight.instrument.imaging.star_catalogue import hipparcos, positions_at, stars_near
    from speclight.instrument.imaging.star_photometry import star_count_rates

    catalogue = hipparcos()
    near = stars_near(catalogue, pointing.centre, reach_deg, imaging.stars.faintest_v_mag)
    stars = catalogue.take(near)
    epoch = 2000.0 + (mid - J2000_UTC) / np.timedelta64(1, "D") / JULIAN_YEAR_DAYS
    directions = positions_at(stars, float(epoch))
    ph = inputs.photometry
    transmission = values_at(inputs.track, ph.transmission, np.array([mid]))[0]
    rates = star_count_rates(
        stars.v_mag,
        stars.b_v,
        ph.wavelength_nm,
        transmission,
        ph.area_m2,
        ph.optics,
        ph.qe,
        ph.band_response,
    )
    return {b: FieldStars(stars.hip, directions, stars.v_mag, rates[:, b]) for b in bands}


def make_frames(inputs: FrameInputs, imaging: Imaging, exposure_s: float) -> Iterator[Frame]:
    """Record every frame (see the module docstring), one at a time.

    Parameters
    ----------
    inputs
        The dataset's quantities.
    imaging
        The imaging section.
    exposure_s
        Exposure time [s] (``imaging.exposure_s`` or ``instrument.exposure_s``).
    """
    det = imaging.detector
    template = Pointing(
        np.array([1.0, 0.0, 0.0]),
        det.scale_arcsec,
        det.position_angle_deg,
        det.width_px,
        det.height_px,
    )
    camera = Camera(
        pointing=template,
        readout=Readout(
            det.read_noise_e, det.gain_e_per_adu, det.bias_adu, det.full_well_e, det.saturation_adu
        ),
        dark_current_e_per_s=det.dark_current_e_per_s,
        oversampling=imaging.oversampling,
        tracking=imaging.tracking,
    )
    bands = _band_indices(inputs, imaging)
    starts, _ = plan_starts(inputs, imaging, exposure_s)
    ph = inputs.photometry
    spec = psf_spec(inputs, imaging)
    fine = det.scale_arcsec / imaging.oversampling
    wavelengths = {b: ph.mean_wavelength_nm(b) for b in bands}
    kernels = {b: psf_kernel(spec, wavelengths[b], fine) for b in bands}
    half = np.timedelta64(round(exposure_s * 0.5e9), "ns")
    mids = np.array([s + half for s in starts], dtype="datetime64[ns]")
    sky_v = _sky_v(inputs, imaging, mids) if starts else np.zeros(0)
    sky_ab = np.nan_to_num(sky_v + V_AB_MINUS_VEGA, nan=np.inf)  # the sky's AB, every band
    sky_rate = {
        b: sky_count_rate_per_s(  # e- s-1 px-1 of a 0 mag arcsec-2 sky, times 10^(-0.4 mu)
            0.0,
            ph.area_m2,
            ph.wavelength_nm,
            ph.optics,
            ph.qe[b],
            ph.band_response[b],
            background_aperture_arcsec2=det.scale_arcsec**2,
        )[0]
        * 10.0 ** (-0.4 * sky_ab)
        for b in bands
    }
    diagonal_deg = np.hypot(det.width_px, det.height_px) / 2.0 * det.scale_arcsec / 3600.0
    for k, (start, mid) in enumerate(zip(starts, mids, strict=True)):
        u_mid = directions_at(inputs.track, np.array([mid]))[0]
        pointing = template.moved_to(u_mid)
        ends = directions_at(inputs.track, np.array([start, start + 2 * half]))
        moved_deg = float(np.degrees(np.arccos(np.clip(ends[0] @ ends[1], -1.0, 1.0))))
        stars = _field_stars(inputs, imaging, pointing, mid, diagonal_deg + moved_deg + 0.1, bands)
        for b in bands:
            yield _one(
                inputs,
                imaging,
                camera,
                k,
                b,
                start,
                mid,
                exposure_s,
                kernels[b],
                pointing,
                stars[b] if stars else None,
                float(sky_rate[b][k] if sky_v.size else 0.0),
                float(sky_v[k]),
                wavelengths[b],
                spec,
            )


def _one(
    inputs: FrameInputs,
    imaging: Imaging,
    camera: Camera,
    k: int,
    b: int,
    start: np.datetime64,
    mid: np.datetime64,
    exposure_s: float,
    psf: F64,
    pointing: Pointing,
    stars: FieldStars | None,
    sky_e_per_s_px: float,
    sky_v: float,
    wavelength_nm: float,
    spec: PsfSpec,
) -> Frame:
    fwhm = fwhm_arcsec(spec, wavelength_nm)
    shape = None
    if inputs.images is not None:
        max_gap_s = (
            max(exposure_s, float(np.median(np.diff(inputs.track.seconds(inputs.track.time_utc)))))
            / 2.0
        )
        shape = target_shape(
            inputs.images, b, mid, pointing.centre, pointing, imaging.oversampling, max_gap_s
        )
    kernel = psf if shape is None else fftconvolve(shape.kernel, psf, mode="full")
    rng = np.random.default_rng([imaging.seed, k, b]) if imaging.noise else None
    exposure = expose(
        camera,
        inputs.track,
        b,
        start,
        exposure_s,
        kernel,
        stars,
        sky_e_per_s_px,
        rng,
        shape.centroid_px if shape is not None else (0.0, 0.0),
    )
    meta = {
        "sky_v_mag_arcsec2": None if np.isnan(sky_v) else sky_v,
        "sky_e_per_s_px": sky_e_per_s_px,
        "psf_fwhm_arcsec": fwhm,
        "psf_wavelength_nm": wavelength_nm,
        "psf_kernel_energy": float(psf.sum()),
        "resolved": bool(shape is not None and shape.rms_radius_arcsec > RESOLVED_FRACTION * fwhm),
        "target_rms_radius_arcsec": None if shape is None else shape.rms_radius_arcsec,
        "image_time_utc": None if shape is None else str(shape.image_time_utc),
    }
    return Frame(k, inputs.photometry.band_names[b], start, mid, exposure_s, exposure, meta)
