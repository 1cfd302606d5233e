"""Reflection maps: each epoch's band reflectance factor placed on a sphere in the body frame.

Kucharski et al. project every measurement onto a sphere fixed to the target along the
**phase vector** (the unit bisector of the target-to-Sun and target-to-observer directions)
in the body frame; the reference paper (Nussbaum et al. 2022, section 5.3, Figures 15-17,
doi:10.3390/aerospace9040214) maps band reflectance factors, range offsets and material
contributions this way. Under coaxial lasers (phase angle 0) the phase vector is the
observer direction itself, and the map is unique; under the Sun one phase vector can be seen
under several phase angles, so a passive map holds what this pass saw.

The sphere is cut into HEALPix pixels (Gorski et al. 2005, doi:10.1086/427976; astropy-healpix)
in the RING ordering, the body frame's +z the north pole and longitude counted from +x towards
+y. :func:`reflection_map` averages the epochs in each pixel: plain arrays in, plain arrays
out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]

#: Finest map: nside 256 is 786,432 pixels of 0.23 deg (6 MB per band and variable in
#: float64), far finer than a pass of thousands of epochs fills.
MAX_NSIDE = 256


def check_nside(nside: int, field: str = "nside") -> int:
    """``nside`` if it is a power of 2 from 1 to ``MAX_NSIDE``, else an :class:`InputError`."""
    if isinstance(nside, bool) or not isinstance(nside, (int, np.integer)):
        raise InputError(f"{field} = {nside!r} must be an integer power of 2", field=field)
    n = int(nside)
    if n < 1 or n > MAX_NSIDE or n & (n - 1):
        raise InputError(
            f"{field} = {n} must be a power of 2 from 1 to {MAX_NSIDE} "
            "(HEALPix: 12 nside^2 pixels; e.g. 8, 16, 32)",
            field=field,
        )
    return n


def pixel_of(direction_xyz: ArrayLike, nside: int) -> I64:
    """RING pixel index (N,) of body-frame directions (N, 3) (need not be unit length).

    Non-finite or zero directions give -1.
    """
    from astropy_healpix import xyz_to_healpix

    d = np.atleast_2d(np.asarray(direction_xyz, dtype=np.float64))
    norm = np.linalg.norm(d, axis=1)
    ok = np.isfinite(norm) & (norm > 0)
    out = np.full(d.shape[0], -1, dtype=np.int64)
    if np.any(ok):
        u = d[ok] / norm[ok, None]
        out[ok] = xyz_to_healpix(
            u[:, 0], u[:, 1], u[:, 2], check_nside(nside, "nside"), order="ring"
        )
    return out


def pixel_centres_deg(nside: int) -> tuple[F64, F64]:
    """Longitude and latitude [degree] (each (12 nside^2,)) of the RING pixel centres."""
    from astropy_healpix import healpix_to_lonlat

    n = check_nside(nside, "nside")
    lon, lat = healpix_to_lonlat(np.arange(12 * n * n), n, order="ring")
    return np.asarray(lon.deg, dtype=np.float64), np.asarray(lat.deg, dtype=np.float64)


def unit_vectors(direction_xyz: ArrayLike) -> F64:
    """Directions (N, 3) scaled to unit length (NaN rows where zero or not finite).

    Used on the mean of several unit vectors (epochs averaged into a bin): its direction is
    the mean direction.
    """
    d = np.atleast_2d(np.asarray(direction_xyz, dtype=np.float64))
    norm = np.linalg.norm(d, axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(np.isfinite(norm) & (norm > 0), d / norm, np.nan)


@dataclass(frozen=True)
class ReflectionMap:
    """Band values averaged over the epochs in each HEALPix pixel (RING, body frame).

    Attributes
    ----------
    nside
        HEALPix resolution (12 nside^2 pixels).
    pixel
        (N,) pixel of each epoch (-1: left out, no direction or no finite value).
    mean
        (B, P) mean over the pixel's epochs of each band's finite values; NaN where none.
    std
        (B, P) their sample standard deviation (ddof 1); NaN where fewer than 2.
    n_samples
        (P,) epochs in the pixel (those with a direction and a finite value in some band).
    n_band
        (B, P) epochs in the pixel with a finite value in that band.
    """

    nside: int
    pixel: I64
    mean: F64
    std: F64
    n_samples: I64
    n_band: I64


def pixel_mean(pixel: ArrayLike, values: ArrayLike, n_pixels: int) -> tuple[F64, I64]:
    """Mean over the epochs of each pixel of ``values`` (N, ...) and the counts (P, ...).

    Epochs with ``pixel`` -1 and non-finite values are left out, element by element; the
    mean is NaN where no value is left.
    """
    p = np.asarray(pixel, dtype=np.int64)
    v = np.asarray(values, dtype=np.float64)
    flat = v.reshape(v.shape[0], -1)
    keep = (p >= 0)[:, None] & np.isfinite(flat)
    pp = np.where(p >= 0, p, 0)
    total = np.zeros((n_pixels, flat.shape[1]))
    count = np.zeros((n_pixels, flat.shape[1]), dtype=np.int64)
    np.add.at(total, pp, np.where(keep, flat, 0.0))
    np.add.at(count, pp, keep.astype(np.int64))
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(count > 0, total / np.maximum(count, 1), np.nan)
    shape = (n_pixels, *v.shape[1:])
    return mean.reshape(shape), count.reshape(shape)


def reflection_map(direction_xyz: ArrayLike, values: ArrayLike, nside: int = 16) -> ReflectionMap:
    """Average band values (N, B) on HEALPix pixels along body-frame directions (N, 3).

    Parameters
    ----------
    direction_xyz
        (N, 3) body-frame direction of each epoch: the phase vector (Sun) or the observer
        direction (coaxial lasers); NaN rows are left out.
    values
        (N, B) band values, e.g. reflectance factors [m2 sr-1] or range offsets [m]; NaN
        values are left out band by band.
    nside
        HEALPix resolution, a power of 2.

    Raises
    ------
    InputError
        A bad ``nside`` or shapes that do not match.
    """
    n = check_nside(nside, "nside")
    d = np.atleast_2d(np.asarray(direction_xyz, dtype=np.float64))
    x = np.asarray(values, dtype=np.float64)
    if x.ndim == 1:
        x = x[:, None]
    if d.ndim != 2 or d.shape[1] != 3 or x.ndim != 2 or x.shape[0] != d.shape[0]:
        raise InputError(
            f"directions {d.shape} and values {x.shape} must be (N, 3) and (N, B)",
            field="direction_xyz",
        )
    pixel = pixel_of(d, n)
    pixel[~np.any(np.isfinite(x), axis=1)] = -1
    n_pix = 12 * n * n
    mean, n_band = pixel_mean(pixel, x, n_pix)
    # two passes for the spread: deviations from the pixel's mean, no cancellation
    dev = x - mean[np.where(pixel >= 0, pixel, 0)]
    dev2, _ = pixel_mean(pixel, dev**2, n_pix)
    with np.errstate(invalid="ignore", divide="ignore"):
        var = np.where(n_band > 1, dev2 * n_band / np.maximum(n_band - 1, 1), np.nan)
    n_samples = np.bincount(pixel[pixel >= 0], minlength=n_pix).astype(np.int64)
    return ReflectionMap(n, pixel, mean.T, np.sqrt(var).T, n_samples, n_band.T)
