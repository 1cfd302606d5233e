"""Derivatives of a reflectivity map's interpolation with respect to the body-frame directions.

:meth:`speclight.maps.map_lookup.ReflectivityMap.intensity_1au` interpolates the map
bilinearly on the HEALPix sphere (astropy-healpix), linearly in phase angle and periodically
linearly in roll (the roll measured in each of the 4 pixel centres' own reference frame).
For a fixed set of 4 pixels every piece is a smooth function of the Sun and observer
directions, so the derivative is the chain rule through the pieces (:func:`intensity_jacobian`):

* **HEALPix weights.** astropy-healpix (``interpolation.c``, ``interpolate_weights``) takes
  two pixels ``0, 1`` of the ring nearest the point (longitudes ``L0 < L1``) and two of the
  next ring towards the point (``2, 3``, ``L2 < L3``, latitude ``B2``), with
  ``x1 = (lon - L0) / (L1 - L0)``, ``x2 = (lon - L2) / (L3 - L2)``,
  ``y = (lat - B0) / (B2 - B0)`` and weights ``(1 - x1)(1 - y), x1 (1 - y), (1 - x2) y,
  x2 y``. Beyond the first or last ring (the polar caps) pixels ``2, 3`` are those across
  the pole, on the same ring, with ``y = (lat - B0) / (+-pi/2 - B0)`` and weights
  ``(1 - x1)(1 - y) + y / 4, x1 (1 - y) + y / 4, y / 4, y / 4``. The pixel centres'
  longitudes and latitudes are constants, so ``dw / dlon`` and ``dw / dlat`` follow; the
  longitude and latitude of the phase vector ``p = normalize(sun + observer)`` are
  ``atan2(p_y, p_x)`` and ``asin(p_z)``. (tests/render/test_map_lookup_grad.py checks that
  these formulas give astropy-healpix's weights.)
* **Roll.** ``roll_i = atan2(u . e_lat_i, u . e_lon_i)`` with ``u = normalize(sun -
  observer)`` and the pixel's fixed reference axes; the roll weights are linear in it.
* **Phase angle.** ``a = arccos(sun . observer)``; the weights are linear in it between two
  stored angles (0 outside them, where the interpolation is clamped). A rotation of the body
  leaves ``a`` unchanged, so for the spin-axis parameters this part is zero.

The derivative is that of the piecewise function: where the point crosses a pixel, ring,
roll or phase-angle cell boundary the interpolant has a kink and the derivative jumps. At
the poles of the body frame (``|lat| = 90 deg``) the longitude is undefined and the
derivative is NaN; at phase angle 0 the roll is undefined and its derivative is taken as 0
(every roll gives the same value there).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.maps.map_geometry import lonlat_deg, roll_reference
from speclight.maps.map_lookup import (
    ReflectivityMap,
    phase_angle_weights,
    plane_axis,
    roll_weights,
)

F64 = NDArray[np.float64]


def healpix_weight_derivatives(
    nside: int, lon_rad: F64, lat_rad: F64, pix: NDArray[np.int64]
) -> tuple[F64, F64, F64]:
    """Weights (4, N) of astropy-healpix's bilinear interpolation at ``lon, lat`` [rad] for
    its pixels ``pix`` (4, N), and their derivatives (4, N) with respect to the longitude
    and the latitude [1/rad] (module docstring)."""
    from astropy_healpix import healpy as hp

    theta, phi = hp.pix2ang(int(nside), pix.ravel(), nest=False)
    lons = phi.reshape(pix.shape)
    lats = (np.pi / 2 - theta).reshape(pix.shape)
    lons = lons + 2 * np.pi * np.round((lon_rad - lons) / (2 * np.pi))  # next to the point
    with np.errstate(invalid="ignore", divide="ignore"):
        dx1 = 1.0 / (lons[1] - lons[0])
        dx2 = 1.0 / (lons[3] - lons[2])
        polar = np.abs(lats[2] - lats[0]) < 1e-12  # the cap: pixels 2, 3 across the pole
        top = np.where(polar, np.sign(lats[0]) * np.pi / 2, lats[2])
        dy = 1.0 / (top - lats[0])
    x1 = (lon_rad - lons[0]) * dx1
    x2 = np.where(polar, 0.0, (lon_rad - lons[2]) * dx2)
    y = (lat_rad - lats[0]) * dy
    q = 0.25 * y
    w = np.stack(
        [
            np.where(polar, (1 - x1) * (1 - y) + q, (1 - x1) * (1 - y)),
            np.where(polar, x1 * (1 - y) + q, x1 * (1 - y)),
            np.where(polar, q, (1 - x2) * y),
            np.where(polar, q, x2 * y),
        ]
    )
    d_lon = np.stack(
        [
            -dx1 * (1 - y),
            dx1 * (1 - y),
            np.where(polar, 0.0, -dx2 * y),
            np.where(polar, 0.0, dx2 * y),
        ]
    )
    d_lat = np.stack(
        [
            np.where(polar, 0.25 - (1 - x1), -(1 - x1)) * dy,
            np.where(polar, 0.25 - x1, -x1) * dy,
            np.where(polar, 0.25, 1 - x2) * dy,
            np.where(polar, 0.25, x2) * dy,
        ]
    )
    return w, d_lon, d_lat


def _unit_derivative(v: F64, dv: F64) -> tuple[F64, F64]:
    """``n = v / |v|`` (N, 3) and its derivative (N, 3, K) for ``dv`` (N, 3, K); zero
    derivative where ``|v|`` is (nearly) 0."""
    norm = np.linalg.norm(v, axis=1)
    safe = np.where(norm > 1e-12, norm, 1.0)
    n = v / safe[:, None]
    dn = (dv - n[:, :, None] * np.einsum("ni,nik->nk", n, dv)[:, None, :]) / safe[:, None, None]
    return n, np.where((norm > 1e-12)[:, None, None], dn, 0.0)


def intensity_jacobian(
    bmap: ReflectivityMap,
    sun_body: ArrayLike,
    observer_body: ArrayLike,
    d_sun: ArrayLike,
    d_observer: ArrayLike,
) -> tuple[F64, F64]:
    """The map's interpolated channels (N, C), as :meth:`ReflectivityMap.intensity_1au`, and
    their derivatives (N, C, K) with respect to K parameters.

    NaN rows where the map gives NaN (phase angle 180 deg, NaN inputs).

    Parameters
    ----------
    bmap
        The map.
    sun_body, observer_body
        Unit vectors (N, 3) towards the Sun and the observer, body frame.
    d_sun, d_observer
        Their derivatives (N, 3, K) (perpendicular to them: changes of direction).
    """
    from astropy import units as u
    from astropy_healpix import bilinear_interpolation_weights

    s = np.atleast_2d(np.asarray(sun_body, dtype=float))
    o = np.atleast_2d(np.asarray(observer_body, dtype=float))
    ds = np.asarray(d_sun, dtype=float)
    do = np.asarray(d_observer, dtype=float)
    n, n_k = s.shape[0], ds.shape[2]
    table = bmap.intensity_W_sr_nm
    n_c = table.shape[-1]
    out = np.full((n, n_c), np.nan)
    jac = np.full((n, n_c, n_k), np.nan)
    with np.errstate(invalid="ignore"):
        cos_a = np.sum(s * o, axis=1)
        ok = np.all(np.isfinite(s + o), axis=1) & (np.linalg.norm(s + o, axis=1) > 1e-12)
    if not np.any(ok):
        return out, jac
    s, o, ds, do, cos_a = s[ok], o[ok], ds[ok], do[ok], np.clip(cos_a[ok], -1.0, 1.0)
    p, dp = _unit_derivative(s + o, ds + do)
    lon_deg, lat_deg = lonlat_deg(p)
    lon, lat = np.radians(lon_deg), np.radians(lat_deg)
    pix, w_astropy = bilinear_interpolation_weights(
        lon_deg * u.deg, lat_deg * u.deg, bmap.header.nside, order="ring"
    )
    pix = np.asarray(pix, dtype=np.int64)
    _, dw_lon, dw_lat = healpix_weight_derivatives(bmap.header.nside, lon, lat, pix)
    with np.errstate(invalid="ignore", divide="ignore"):
        rho2 = p[:, 0] ** 2 + p[:, 1] ** 2
        d_lon = (p[:, 0, None] * dp[:, 1] - p[:, 1, None] * dp[:, 0]) / rho2[:, None]  # (n, K)
        d_lat = dp[:, 2] / np.sqrt(rho2)[:, None]
    dw_pix = dw_lon[:, :, None] * d_lon[None] + dw_lat[:, :, None] * d_lat[None]  # (4, n, K)
    # phase angle: linear weights between the stored angles, 0 where clamped
    a = np.arccos(cos_a)
    stored = bmap.header.phase_angle_deg
    j, w_phase = phase_angle_weights(stored, np.degrees(a))
    dw_phase = np.zeros((2, a.size, n_k))
    if stored.size > 1:
        inside = (np.degrees(a) > stored[0]) & (np.degrees(a) < stored[-1])
        with np.errstate(invalid="ignore", divide="ignore"):
            da = -(np.einsum("ni,nik->nk", o, ds) + np.einsum("ni,nik->nk", s, do))
            da_deg = np.degrees(da / np.sin(a)[:, None])
        dt = np.where(inside[:, None], da_deg / (stored[j[1]] - stored[j[0]])[:, None], 0.0)
        dw_phase = np.stack([-dt, dt])
    # roll: u = normalize(sun - observer), 0 derivative at phase angle 0
    u_vec = plane_axis(s, o)
    _, du = _unit_derivative(s - o, ds - do)
    n_r = bmap.header.roll_deg.size
    acc = np.zeros((a.size, n_c))
    dacc = np.zeros((a.size, n_c, n_k))
    for i in range(4):
        e_lon, e_lat = roll_reference(bmap.direction_body[pix[i]])
        xr, yr = np.sum(u_vec * e_lon, axis=1), np.sum(u_vec * e_lat, axis=1)
        roll = np.arctan2(yr, xr)
        d_roll = (
            xr[:, None] * np.einsum("ni,nik->nk", e_lat, du)
            - yr[:, None] * np.einsum("ni,nik->nk", e_lon, du)
        ) / np.maximum(xr**2 + yr**2, 1e-300)[:, None]
        k, w_roll = roll_weights(n_r, roll)
        dw_roll = np.stack([-d_roll, d_roll]) * (n_r / (2 * np.pi))
        for jj in range(2):
            for kk in range(2):
                v = table[pix[i], j[jj], k[kk]].astype(float)  # (n, C)
                w = w_astropy[i] * w_phase[jj] * w_roll[kk]
                acc += w[:, None] * v
                dw = (
                    dw_pix[i] * (w_phase[jj] * w_roll[kk])[:, None]
                    + (w_astropy[i] * w_roll[kk])[:, None] * dw_phase[jj]
                    + (w_astropy[i] * w_phase[jj])[:, None] * dw_roll[kk]
                )
                dacc += v[:, :, None] * dw[:, None, :]
    out[ok] = acc
    jac[ok] = dacc
    return out, jac
