"""Geometry conventions of reflectivity maps: directions, phase angle and roll.

A reflectivity map tabulates the target's intensity over the body-frame **phase vector**
``p`` (the bisector of the Sun and observer directions, Nussbaum et al. 2022, Fig. 1), the
**phase angle** ``a`` (between Sun and observer) and the **roll** ``r`` of the Sun-observer
plane about ``p``:

* directions: HEALPix pixel centres, RING ordering, ``nside`` the smallest power of two with
  ``12 nside^2 >= N``; longitude ``atan2(p_y, p_x)``, latitude ``asin(p_z)`` in the body frame;
* roll reference at ``p``: ``e_lon = normalize(z x p)`` (east) and ``e_lat = p x e_lon``
  (north); where ``p`` is within 1e-9 of the z axis, ``e_lon = y`` is used (so ``e_lat = -x``
  at the north pole);
* ``u = cos(r) e_lon + sin(r) e_lat`` is the unit vector in the Sun-observer plane,
  perpendicular to ``p``, on the Sun's side; then
  ``sun = cos(a/2) p + sin(a/2) u`` and ``observer = cos(a/2) p - sin(a/2) u``.

A scenario epoch's ``(sun_body, observer_body)`` maps back with :func:`map_coordinates`:
``p = normalize(sun + observer)``, ``a = arccos(sun . observer)``,
``u = normalize(sun - observer)``, ``r = atan2(u . e_lat, u . e_lon)`` in ``[0, 2 pi)``. At
``a = 0`` the roll is undefined (returned as 0; any roll gives the same render).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError

F64 = NDArray[np.float64]
#: Fewest directions of a map: HEALPix nside 1 (12 pixels).
MIN_DIRECTIONS = 12
#: Largest HEALPix nside of a map (12 * 1024^2 = 12.6 million directions).
MAX_NSIDE = 1024


def nside_for(n_directions: int) -> int:
    """Smallest power-of-two HEALPix ``nside`` with ``12 nside^2 >= n_directions``."""
    n = int(n_directions)
    if n < MIN_DIRECTIONS:
        raise InputError(
            f"directions = {n_directions} must be >= {MIN_DIRECTIONS} (HEALPix nside 1)",
            field="directions",
        )
    nside = 1
    while 12 * nside * nside < n:
        nside *= 2
    if nside > MAX_NSIDE:
        raise InputError(
            f"directions = {n_directions} needs HEALPix nside {nside}; accepted: at most "
            f"{12 * MAX_NSIDE**2} directions (nside {MAX_NSIDE})",
            field="directions",
        )
    return nside


def healpix_directions(nside: int) -> F64:
    """Unit vectors (12 nside^2, 3) of the HEALPix pixel centres, RING ordering."""
    from astropy_healpix import healpy as hp

    x, y, z = hp.pix2vec(int(nside), np.arange(12 * int(nside) ** 2), nest=False)
    return np.stack([x, y, z], axis=1).astype(float)


def roll_reference(p: ArrayLike) -> tuple[F64, F64]:
    """``(e_lon, e_lat)`` (N, 3): the roll reference axes at phase vectors ``p`` (N, 3)."""
    p = np.atleast_2d(np.asarray(p, dtype=float))
    z = np.array([0.0, 0.0, 1.0])
    e = np.cross(z, p)
    norm = np.linalg.norm(e, axis=1)
    polar = norm < 1e-9
    e[polar] = np.array([0.0, 1.0, 0.0])
    e /= np.where(polar, 1.0, norm)[:, None]
    return e, np.cross(p, e)


def sun_observer(p: ArrayLike, phase_angle_rad: ArrayLike, roll_rad: ArrayLike) -> tuple[F64, F64]:
    """Sun and observer unit vectors (N, 3) for phase vectors ``p`` (N, 3), phase angles and
    rolls (broadcast to N) [rad] (module docstring)."""
    p = np.atleast_2d(np.asarray(p, dtype=float))
    a = np.broadcast_to(np.asarray(phase_angle_rad, dtype=float), (len(p),))[:, None]
    r = np.broadcast_to(np.asarray(roll_rad, dtype=float), (len(p),))[:, None]
    e_lon, e_lat = roll_reference(p)
    u = np.cos(r) * e_lon + np.sin(r) * e_lat
    return np.cos(a / 2) * p + np.sin(a / 2) * u, np.cos(a / 2) * p - np.sin(a / 2) * u


def map_coordinates(sun: ArrayLike, observer: ArrayLike) -> tuple[F64, F64, F64]:
    """Phase vector (N, 3), phase angle (N,) [rad] and roll (N,) [rad, 0..2 pi) of epochs.

    The inverse of :func:`sun_observer`. Rows with non-finite or zero inputs, and phase angle
    180 deg (no phase vector), give NaN.
    """
    s = np.atleast_2d(np.asarray(sun, dtype=float))
    o = np.atleast_2d(np.asarray(observer, dtype=float))
    with np.errstate(invalid="ignore", divide="ignore"):
        s = s / np.linalg.norm(s, axis=1)[:, None]
        o = o / np.linalg.norm(o, axis=1)[:, None]
        b = s + o
        nb = np.linalg.norm(b, axis=1)
        p = np.where((nb > 1e-12)[:, None], b / nb[:, None], np.nan)
        a = np.arccos(np.clip(np.sum(s * o, axis=1), -1.0, 1.0))
        d = s - o
        nd = np.linalg.norm(d, axis=1)
        u = d / np.where(nd > 1e-12, nd, 1.0)[:, None]
    e_lon, e_lat = roll_reference(np.nan_to_num(p))
    roll = np.mod(np.arctan2(np.sum(u * e_lat, axis=1), np.sum(u * e_lon, axis=1)), 2 * np.pi)
    roll = np.where(nd > 1e-12, roll, 0.0)
    bad = ~np.all(np.isfinite(p), axis=1)
    a[bad] = np.nan
    roll[bad] = np.nan
    return p, a, roll


def lonlat_deg(p: ArrayLike) -> tuple[F64, F64]:
    """Body-frame longitude and latitude [deg] of unit vectors (N, 3)."""
    p = np.atleast_2d(np.asarray(p, dtype=float))
    lon = np.degrees(np.mod(np.arctan2(p[:, 1], p[:, 0]), 2 * np.pi))
    lat = np.degrees(np.arcsin(np.clip(p[:, 2], -1.0, 1.0)))
    return lon, lat
