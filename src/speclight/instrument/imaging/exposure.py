"""One exposure: the target's path, the stars and the sky on the detector, then the readout.

An exposure from ``start`` to ``start + exposure_s`` is cut into ``n`` equal sub-steps,
enough that the field moves at most half a fine pixel per step; each source is a point at
every sub-step's middle carrying the light of that sub-step (the midpoint rule of the
exposure's integral), rasterised by :func:`~speclight.instrument.imaging.streak_raster.add_source`.

Tracking:

* ``sidereal``: the telescope holds the field: the frame's centre is the target's direction
  at mid-exposure, the stars are points and the target streaks through the centre;
* ``target``: the telescope follows the target (an equatorial mount, north kept at the
  same position angle): the target stays at the centre and the stars streak the other way.

The frame's WCS is that of mid-exposure.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from speclight.instrument.imaging.detector_readout import Readout, read_out
from speclight.instrument.imaging.sky_projection import Pointing, sky_to_pixel
from speclight.instrument.imaging.streak_raster import add_source
from speclight.instrument.imaging.target_path import Track, directions_at, values_at

F64 = NDArray[np.float64]

#: Most sub-steps of one exposure (a LEO streak of 10^4 pixels at 4 sub-pixels: 8e4).
MAX_SUBSTEPS = 200_000
#: Fewest sub-steps (the count rate's change within a short exposure still sampled).
MIN_SUBSTEPS = 8


@dataclass(frozen=True)
class Camera:
    """The camera and how it is used.

    Attributes
    ----------
    pointing
        Detector geometry (its ``centre`` is replaced per exposure).
    readout
        Noise, gain, bias, full well, ADC.
    dark_current_e_per_s
        Dark current per pixel [e- s-1].
    oversampling
        Fine pixels per pixel and axis.
    tracking
        ``sidereal`` or ``target``.
    """

    pointing: Pointing
    readout: Readout
    dark_current_e_per_s: float = 0.0
    oversampling: int = 4
    tracking: Literal["sidereal", "target"] = "sidereal"


@dataclass(frozen=True)
class FieldStars:
    """Stars near the field, each of shape (S,) or (S, 3).

    Attributes
    ----------
    hip
        Catalogue numbers.
    directions
        (S, 3) ICRS unit vectors at the exposure's epoch.
    v_mag
        V magnitudes.
    count_rate
        Photo-electron rate in the frame's band [s-1].
    """

    hip: NDArray[np.int64]
    directions: F64
    v_mag: F64
    count_rate: F64


@dataclass
class Exposure:
    """A recorded frame and its truth.

    Attributes
    ----------
    adu
        (rows, columns) what the camera writes [ADU].
    mean_e
        The expected electrons per pixel [e-] (no noise).
    saturated
        Pixels at the full well or the ADC's top.
    pointing
        The frame's geometry at mid-exposure (its WCS).
    truth
        Target and stars: positions, streak ends, electrons (see docs/frames.md).
    """

    adu: NDArray[Any]
    mean_e: F64
    saturated: NDArray[np.bool_]
    pointing: Pointing
    truth: dict[str, Any] = field(default_factory=dict)


def substep_count(track: Track, start: np.datetime64, exposure_s: float, camera: Camera) -> int:
    """Sub-steps so that the target moves at most half a fine pixel per step."""
    ends = np.array([start, start + np.timedelta64(round(exposure_s * 1e9), "ns")])
    u = directions_at(track, ends)
    moved_arcsec = np.degrees(np.arccos(np.clip(u[0] @ u[1], -1.0, 1.0))) * 3600.0
    fine_px = moved_arcsec / camera.pointing.scale_arcsec * camera.oversampling
    return int(np.clip(np.ceil(2.0 * fine_px), MIN_SUBSTEPS, MAX_SUBSTEPS))


def _mid_times(start: np.datetime64, exposure_s: float, n: int) -> NDArray[np.datetime64]:
    offsets_ns = np.rint((np.arange(n) + 0.5) / n * exposure_s * 1e9).astype(np.int64)
    return np.asarray(start, dtype="datetime64[ns]") + offsets_ns.astype("timedelta64[ns]")


def _pixels(u: F64, centres: F64 | None, pointing: Pointing) -> tuple[F64, F64]:
    """Pixels of directions ``u`` (P, 3) for a fixed pointing, or one per ``centres`` row."""
    return sky_to_pixel(u, pointing, centres)


def expose(
    camera: Camera,
    track: Track,
    band: int,
    start: np.datetime64,
    exposure_s: float,
    kernel: F64,
    stars: FieldStars | None,
    sky_e_per_s_px: float,
    rng: np.random.Generator | None,
    target_centroid_px: tuple[float, float] = (0.0, 0.0),
) -> Exposure:
    """Record one frame.

    Parameters
    ----------
    camera
        The camera.
    track
        The target's per-epoch direction, rates and count rates.
    band
        Index of the frame's band in ``track.count_rate``.
    start
        Start of the exposure (UTC ``datetime64``).
    exposure_s
        Exposure time [s].
    kernel
        PSF on the fine grid (convolved with the target's shape when resolved).
    stars
        Stars near the field, or ``None``.
    sky_e_per_s_px
        Sky photo-electrons per pixel and second in the band.
    rng
        Random generator, ``None`` for a noiseless frame.
    target_centroid_px
        Offset of the target's light centroid from its centre of mass [px] (resolved
        targets), for the truth.

    Returns
    -------
    Exposure
    """
    start = start.astype("datetime64[ns]")
    n = substep_count(track, start, exposure_s, camera)
    dt = exposure_s / n
    t = _mid_times(start, exposure_s, n)
    u = directions_at(track, t)
    ends = directions_at(
        track, np.array([start, start + np.timedelta64(round(exposure_s * 1e9), "ns")])
    )
    mid = directions_at(track, _mid_times(start, exposure_s, 1))[0]
    pointing = camera.pointing.moved_to(mid)
    tracked = u if camera.tracking == "target" else None
    rate = np.nan_to_num(values_at(track, track.count_rate[:, band], t), nan=0.0)
    electrons = rate * dt
    image = np.zeros((pointing.height_px, pointing.width_px))
    tx, ty = _pixels(u, tracked, pointing)
    landed = add_source(image, tx, ty, electrons, kernel, camera.oversampling)
    ex, ey = _pixels(ends, ends if camera.tracking == "target" else None, pointing)
    total = float(electrons.sum())
    cx = float((electrons * tx).sum() / total) + target_centroid_px[0] if total > 0 else np.nan
    cy = float((electrons * ty).sum() / total) + target_centroid_px[1] if total > 0 else np.nan
    truth: dict[str, Any] = {
        "target": {
            "x": cx,
            "y": cy,
            "electrons": total,
            "electrons_on_frame": landed,
            "start_x": float(ex[0]),
            "start_y": float(ey[0]),
            "end_x": float(ex[1]),
            "end_y": float(ey[1]),
        },
        "substeps": n,
    }
    truth["stars"] = _add_stars(
        image, camera, stars, u, tracked, ends, pointing, kernel, exposure_s
    )
    background = (sky_e_per_s_px + camera.dark_current_e_per_s) * exposure_s
    image += background
    adu, saturated = read_out(image, camera.readout, rng)
    truth["background_e_per_px"] = background
    truth["saturated_pixels"] = int(saturated.sum())
    return Exposure(adu, image, saturated, pointing, truth)


def _add_stars(
    image: F64,
    camera: Camera,
    stars: FieldStars | None,
    u: F64,
    tracked: F64 | None,
    ends: F64,
    pointing: Pointing,
    kernel: F64,
    exposure_s: float,
) -> list[dict[str, Any]]:
    """Rasterise the stars; the truth of those that land on the frame."""
    if stars is None or stars.hip.size == 0:
        return []
    n = u.shape[0]
    out = []
    for s in range(stars.hip.size):
        d = np.broadcast_to(stars.directions[s], (n if tracked is not None else 1, 3))
        x, y = _pixels(np.ascontiguousarray(d), tracked, pointing)
        e = np.full(x.size, stars.count_rate[s] * exposure_s / x.size)
        landed = add_source(image, x, y, e, kernel, camera.oversampling)
        if landed <= 0:
            continue
        two = np.broadcast_to(stars.directions[s], (2, 3))
        sx, sy = _pixels(np.ascontiguousarray(two), ends if tracked is not None else None, pointing)
        out.append(
            {
                "hip": int(stars.hip[s]),
                "v_mag": float(stars.v_mag[s]),
                "x": float(x.mean()),
                "y": float(y.mean()),
                "electrons": float(e.sum()),
                "electrons_on_frame": landed,
                "start_x": float(sx[0]),
                "start_y": float(sy[0]),
                "end_x": float(sx[1]),
                "end_y": float(sy[1]),
            }
        )
    return out
