"""What a render returns."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray


@dataclass
class RenderImage:
    """Hyperspectral image and depth map of one epoch, orthographic view along the line of sight.

    ``radiance_W_m2_sr_nm`` (H, W, L) is the reflected radiance in each pixel;
    ``depth_m`` (H, W) the distance along the line of sight behind the plane through the target
    centre that faces the observer (NaN where the pixel misses the target), so the range to a
    pixel is ``range_m + depth_m``; ``part_index`` (H, W) the part seen (-1: none).
    Row 0 is the top of the image; ``up_body`` and ``right_body`` are the body-frame directions
    of the image axes; ``pixel_size_m`` is the pixel pitch [m]. ``stokes_qu_W_m2_sr_nm``
    (H, W, L, 2) is the Stokes Q, U of each pixel's radiance in the sky's north-east frame
    (as :attr:`RenderResult.stokes_W_sr_nm`), single mode with polarisation only, else None;
    :func:`speclight.render.single.render_single_polarized` leaves it referenced to the
    scattering plane's normal (U = 0) and :func:`speclight.render.render_intensity` rotates it.
    """

    epoch: int
    radiance_W_m2_sr_nm: NDArray[np.float64]
    depth_m: NDArray[np.float64]
    part_index: NDArray[np.int64]
    pixel_size_m: float
    right_body: NDArray[np.float64]
    up_body: NDArray[np.float64]
    stokes_qu_W_m2_sr_nm: NDArray[np.float64] | None = None


@dataclass
class RenderResult:
    """Radiant intensity of the target toward the observer.

    Attributes
    ----------
    intensity_W_sr_nm
        (N, L) radiant intensity [W sr-1 nm-1]; NaN rows where the epoch's inputs were NaN.
    intensity_std_W_sr_nm
        (N, L) Monte Carlo standard error of ``intensity_W_sr_nm`` [W sr-1 nm-1]; zero in
        ``single`` mode, whose only error is the pixel discretisation.
    ok
        (N,) True where the epoch was rendered.
    variant
        Ray-casting engine: a Mitsuba variant name, or ``"numpy"``.
    mode
        ``single`` or ``path``.
    images
        Epoch index -> :class:`RenderImage` for the epochs asked for in ``keep_images_for``.
    stokes_W_sr_nm
        (N, L, 3) Stokes Q, U, V of the intensity [W sr-1 nm-1] in the sky's north-east
        frame (:mod:`speclight.render.polarization`); None unless polarisation was asked.
    stokes_std_W_sr_nm
        (N, L, 3) their Monte Carlo standard errors (zero in single mode).
    outside_support_W_sr_nm
        (N, L) the part of ``intensity_W_sr_nm`` reflected by measured tables outside their
        measured support (their fitted extension, :mod:`speclight.target.brdf_table`);
        None when no material has a support (no lab table; path mode, which has none).
    """

    intensity_W_sr_nm: NDArray[np.float64]
    intensity_std_W_sr_nm: NDArray[np.float64]
    ok: NDArray[np.bool_]
    variant: str
    mode: str
    images: dict[int, RenderImage] = field(default_factory=dict)
    stokes_W_sr_nm: NDArray[np.float64] | None = None
    stokes_std_W_sr_nm: NDArray[np.float64] | None = None
    outside_support_W_sr_nm: NDArray[np.float64] | None = None
