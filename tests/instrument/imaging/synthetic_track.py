"""A target on a great circle at a constant angular rate: a track whose truth is closed form.

``u(t) = cos(w t) c + sin(w t) d`` with ``c`` the direction at t = 0 and ``d`` the unit
tangent at position angle ``pa`` (north through east); its rate is ``w`` along ``d``, and
(RA, Dec) with their rates follow from it exactly.
"""

from __future__ import annotations

import numpy as np

from speclight.attitude.quaternion import radec_from_unit_vector, unit_vector_from_radec
from speclight.instrument.imaging.frame_inputs import FrameInputs, Photometry
from speclight.instrument.imaging.sky_projection import east_north
from speclight.instrument.imaging.target_path import Track

T0 = np.datetime64("2021-03-10T22:00:00", "ns")


def great_circle_track(
    ra0_deg: float,
    dec0_deg: float,
    rate_arcsec_s: float,
    pa_deg: float,
    count_rate: float,
    span_s: float = 10.0,
    step_s: float = 1.0,
) -> Track:
    """Epochs from 0 to ``span_s``; the target passes (ra0, dec0) at the middle."""
    t = np.arange(0.0, span_s + step_s / 2, step_s)
    c = unit_vector_from_radec(ra0_deg, dec0_deg)
    e, n = east_north(c)
    pa = np.radians(pa_deg)
    d = np.sin(pa) * e + np.cos(pa) * n
    w = np.radians(rate_arcsec_s / 3600.0)
    a = w * (t - span_s / 2)
    u = np.cos(a)[:, None] * c + np.sin(a)[:, None] * d
    du = w * (-np.sin(a)[:, None] * c + np.cos(a)[:, None] * d)  # rad s-1
    ee, nn = east_north(u)
    ra, dec = radec_from_unit_vector(u)
    return Track(
        time_utc=T0 + (t * 1e9).astype("timedelta64[ns]"),
        ra_deg=ra,
        dec_deg=dec,
        ra_cos_dec_rate_deg_s=np.degrees(np.einsum("ij,ij->i", du, ee)),
        dec_rate_deg_s=np.degrees(np.einsum("ij,ij->i", du, nn)),
        elevation_deg=np.full(t.size, 60.0),
        count_rate=np.full((t.size, 1), float(count_rate)),
        sun_elevation_deg=np.full(t.size, -30.0),
    )


def flat_photometry(n_epochs: int) -> Photometry:
    """One grey band (Bessell V response window) with optics, QE and transmission 1."""
    wl = np.arange(300.0, 1101.0, 5.0)
    band = ((wl >= 480) & (wl <= 700)).astype(float)[None, :]
    return Photometry(
        band_names=("V",),
        wavelength_nm=wl,
        band_response=band,
        qe=np.ones((1, wl.size)),
        optics=np.ones(wl.size),
        transmission=np.ones((n_epochs, wl.size)),
        aperture_diameter_m=0.5,
        obstruction_diameter_m=0.15,
    )


def synthetic_inputs(track: Track) -> FrameInputs:
    """Frame inputs of a synthetic track (no kept images)."""
    return FrameInputs(
        track=track,
        photometry=flat_photometry(track.time_utc.size),
        images=None,
        site=(48.78, 9.20, 355.0),
        scenario_yaml="",
    )
