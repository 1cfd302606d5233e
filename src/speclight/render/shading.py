"""Per-hit shading geometry shared by every single-scattering evaluation (Sun and lasers).

For a surface point with unit normal ``n`` (flipped toward the viewer: surfaces are
two-sided), a light direction ``s`` and a viewing direction ``o`` (unit vectors from the point):
the half vector ``h = (s + o) / |s + o|``, the cosines ``n . s``, ``n . o``, ``n . h``,
``s . h`` (half the phase angle), and whether the mirror direction of ``o`` falls inside the
solar disk (the glint of a smooth mirror, :data:`SUN_COS`).
The Sun render (:mod:`.single`), the laser returns (:mod:`.laser_returns`) and the
multi-bounce laser paths (:mod:`.laser_multibounce`) all use these functions.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from speclight.illumination.solar import SOLAR_ANGULAR_RADIUS_RAD

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


def sun_disk_sin2() -> float:
    """sin^2 of the angular radius of the path mode's solar disk: the solar disk
    (:data:`~speclight.illumination.SOLAR_ANGULAR_RADIUS_RAD`), rounded so that
    ``1 - cos(theta)`` is a whole number of float32 steps (2^-24).

    Mitsuba samples a sphere emitter by its cone with the density
    ``1 / (2 pi (1 - cos theta_max))``, ``cos theta_max`` computed in float32 from sin^2:
    for the Sun (1 - cos = 1.08e-5, 181 float32 steps) an arbitrary radius is off by up to
    half a step, a bias of up to 0.3 % in every sunlit pixel. With 1 - cos an exact number
    of steps the float32 value is exact; the disk's solid angle is 0.23 % below the Sun's
    (radius 0.2661 instead of 0.2665 deg; the Sun's own varies by 3.4 % over a year), so the
    radiance of a mirror glint is 0.23 % above the single mode's (which uses
    :data:`SUN_SOLID_ANGLE_SR`); irradiance and glint power are unchanged.
    """
    step = 2.0**-24
    delta = round((1.0 - np.cos(SOLAR_ANGULAR_RADIUS_RAD)) / step) * step
    return float(2.0 * delta - delta * delta)


SUN_COS = float(np.cos(SOLAR_ANGULAR_RADIUS_RAD))
SUN_SOLID_ANGLE_SR = float(2.0 * np.pi * (1.0 - SUN_COS))


def dot_rows(a: F64, b: F64) -> F64:
    """Row-wise dot products of two (M, 3) arrays."""
    return np.asarray(np.einsum("mk,mk->m", a, b))


def half_vectors(s: F64, o: F64) -> F64:
    """Unit half vectors (M, 3) of light ``s`` and view ``o``; ``s`` where they are opposite."""
    half = s + o
    norm = np.linalg.norm(half, axis=1, keepdims=True)
    return np.asarray(np.where(norm > 1e-12, half / np.maximum(norm, 1e-300), s))


def mirror_in_sun(n: F64, cos_o: F64, o: F64, s: F64) -> F64:
    """1.0 where the mirror direction of ``o`` about ``n`` falls inside the solar disk around
    ``s``, else 0.0 (M,); ``cos_o = n . o``."""
    mirror = 2.0 * cos_o[:, None] * n - o
    return (dot_rows(mirror, s) >= SUN_COS).astype(float)


@dataclass
class VisibleHits:
    """The primary rays of one batch of epochs that see a surface (two-sided, normal flipped
    toward the receiver).

    Attributes
    ----------
    epochs
        (b,) indices of the batch's epochs (into the caller's arrays).
    ep
        (M,) slot of each hit's epoch in the batch (0..b-1).
    o
        (b, 3) unit vectors from the target to the receiver.
    n, cos_o
        (M, 3) normals facing the receiver and (M,) their cosine with ``o``.
    hit, t
        (M,) index of the ray in the batch and its distance to the hit [m].
    rel_o
        (M,) ``(p - c) . o`` of each hit point ``p`` relative to the centre of mass ``c`` [m].
    part
        (M,) part index of each hit.
    origin
        (b * pixels, 3) the batch's ray origins.
    """

    epochs: I64
    ep: I64
    o: F64
    n: F64
    cos_o: F64
    hit: I64
    t: F64
    rel_o: F64
    part: I64
    origin: F64

    @property
    def pixels(self) -> int:
        """Rays per epoch."""
        return len(self.origin) // len(self.epochs)

    def position(self, idx: I64) -> F64:
        """Hit points (len(idx), 3) of the hits ``idx`` (the primary rays travel along -o)."""
        return np.asarray(self.origin[self.hit[idx]] - self.t[idx, None] * self.o[self.ep[idx]])
