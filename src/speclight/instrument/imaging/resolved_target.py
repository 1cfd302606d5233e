"""A target that is not a point: its rendered image laid on the sky.

The pipeline keeps renders of the target (``render.save_images_at``): an orthographic
image across the line of sight, pixel pitch ``p`` at the target, axes ``right`` and ``up``
(as the observer sees them). A pixel at ``(x, y)`` [m] from the image centre (the body
origin, which the ephemeris follows) is the offset ``d = x right + y up`` at range ``r``,
seen at ``(xi, eta) = (d . e, d . n) / r`` east and north of the target's direction. Its
light in the band (radiance x the line of sight's transmission x the band's detection chain)
weights it. The result is a kernel on the fine grid that the PSF is convolved with; the
frame's brightness still comes from the light curve, the image gives only the shape.

The target counts as resolved when the RMS radius of its light exceeds
:data:`RESOLVED_FRACTION` of the PSF's FWHM (a point source's image then widens by less than
about 2 %); the kernel is used in either case (for a point it is a single fine pixel).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from speclight.instrument.imaging.frame_inputs import KeptImages
from speclight.instrument.imaging.psf import shape_kernel
from speclight.instrument.imaging.sky_projection import Pointing, east_north, offsets_to_pixels

F64 = NDArray[np.float64]

#: RMS radius of the target's light, over the PSF's FWHM, above which it counts as resolved.
RESOLVED_FRACTION = 0.1


@dataclass(frozen=True)
class TargetShape:
    """The target's light on the fine grid.

    Attributes
    ----------
    kernel
        (K, K) fine-grid kernel, sum 1, the target's centre of mass at its middle.
    centroid_px
        Offset (x, y) of the light's centroid from the centre of mass [detector px].
    rms_radius_arcsec
        RMS radius of the light about its centroid [arcsec].
    image_time_utc
        Epoch of the render used.
    """

    kernel: F64
    centroid_px: tuple[float, float]
    rms_radius_arcsec: float
    image_time_utc: np.datetime64


def target_shape(
    images: KeptImages,
    band: int,
    time_utc: np.datetime64,
    direction: F64,
    pointing: Pointing,
    oversampling: int,
    max_gap_s: float,
) -> TargetShape | None:
    """The target's shape from the render nearest ``time_utc``, or ``None`` if none is
    within ``max_gap_s`` or it holds no light in the band.

    Parameters
    ----------
    images
        The kept renders.
    band
        Band index.
    time_utc
        Mid-exposure.
    direction
        (3,) the target's direction (ICRS).
    pointing
        The frame's geometry (plate scale, position angle).
    oversampling
        Fine pixels per pixel.
    max_gap_s
        Largest accepted time between the render and ``time_utc`` [s].
    """
    gap_s = np.abs(
        (images.time_utc - np.asarray(time_utc, dtype="datetime64[ns]")) / np.timedelta64(1, "s")
    )
    m = int(np.argmin(gap_s))
    if gap_s[m] > max_gap_s:
        return None
    light = images.light[m, band]
    h, w = light.shape
    rows, cols = np.nonzero(light > 0)
    if rows.size == 0:
        return None
    weight = light[rows, cols]
    pitch = images.pixel_size_m[m]
    x_m = (cols + 0.5 - w / 2.0) * pitch
    y_m = (h / 2.0 - rows - 0.5) * pitch
    d = x_m[:, None] * images.right_icrs[m] + y_m[:, None] * images.up_icrs[m]
    east, north = east_north(direction)
    xi_deg = np.degrees(d @ east / images.range_m[m])
    eta_deg = np.degrees(d @ north / images.range_m[m])
    dx, dy = offsets_to_pixels(xi_deg, eta_deg, pointing)
    kernel, centroid = shape_kernel(np.stack([dx, dy], axis=1) * oversampling, weight)
    total = weight.sum()
    mean_xi, mean_eta = (weight * xi_deg).sum() / total, (weight * eta_deg).sum() / total
    var = (weight * ((xi_deg - mean_xi) ** 2 + (eta_deg - mean_eta) ** 2)).sum() / total
    return TargetShape(
        kernel=kernel,
        centroid_px=(float(centroid[0] / oversampling), float(centroid[1] / oversampling)),
        rms_radius_arcsec=float(np.sqrt(var) * 3600.0),
        image_time_utc=images.time_utc[m],
    )
