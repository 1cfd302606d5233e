"""Polarisation of reflected sunlight: Fresnel Mueller matrices and the sky's Stokes frame.

Sunlight is unpolarised, so only the first column of a surface's Mueller matrix matters:
the reflected Stokes vector is ``f * (M00, M10, M20, M30)``. For a smooth interface (and,
in the single-scattering microfacet model, for each microfacet, whose normal is the half
vector of the Sun and observer directions) with its Stokes frame referenced to the
direction perpendicular to the plane of incidence (the s direction)

    M[:, 0] = ((R_s + R_p) / 2, (R_s - R_p) / 2, 0, 0)

with the Fresnel reflectances ``R_s = |r_s|^2``, ``R_p = |r_p|^2`` of the complex index
``n + i k`` (Born & Wolf, Principles of Optics, 7th ed., sec. 1.5.2 and 14.2; Collett,
Polarized Light, 2nd ed., ch. 8; the microfacet form: Baek et al. 2018, "Simultaneous
acquisition of polarimetric SVBRDF and normals", ACM TOG 37(6) 268, eq. 4). The s/p phase
difference enters only the U, V rows of the columns for polarised light: with unpolarised
incidence single scattering gives V = 0. The plane of incidence of a microfacet whose
normal is the half vector contains the Sun and observer directions: it is the scattering
plane, the same for every pixel of an epoch.

The sky frame (IAU 1974, Transactions of the IAU XVB, 166; Hamaker & Bregman 1996, A&AS
117, 161): at the observer, with the line of sight ``d`` toward the target, north ``N`` is
the direction of the celestial pole (the GCRS z axis) projected on the plane of the sky,
east ``E = z x d / |z x d|`` (increasing right ascension), ``N = d x E``. Q > 0 is
polarisation along north, U > 0 along position angle 45 deg (north through east).
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError
from speclight.target.bsdf_models import BSDF_FORMS
from speclight.target.materials import Material

F64 = NDArray[np.float64]


def fresnel_sp(cos_theta: ArrayLike, eta: ArrayLike) -> tuple[F64, F64]:
    """Fresnel reflectances ``(R_s, R_p)`` of a vacuum / (n + i k) interface.

    Parameters
    ----------
    cos_theta
        Cosine of the angle of incidence, in [0, 1] (broadcast against ``eta``).
    eta
        Complex refractive index ``n + i k`` (real for a dielectric).

    Returns
    -------
    tuple of numpy.ndarray
        ``|r_s|^2`` and ``|r_p|^2`` with ``r_s = (c - n c_t) / (c + n c_t)``,
        ``r_p = (n c - c_t) / (n c + c_t)``, ``c_t = sqrt(1 - (1 - c^2) / n^2)`` (complex
        Snell's law; Born & Wolf sec. 14.2). Their mean is
        :func:`speclight.target.optical_constants.fresnel_reflectance`.
    """
    c = np.clip(np.asarray(cos_theta, dtype=float), 0.0, 1.0)
    n = np.asarray(eta, dtype=complex)
    cos_t = np.sqrt(1.0 - (1.0 - c * c) / (n * n))
    r_s = (c - n * cos_t) / (c + n * cos_t)
    r_p = (n * c - cos_t) / (n * c + cos_t)
    return np.abs(r_s) ** 2, np.abs(r_p) ** 2


def linear_factor(cos_theta: ArrayLike, eta: ArrayLike) -> F64:
    """``M10 = (R_s - R_p) / 2``: the Stokes Q of reflected unpolarised light of unit
    intensity per unit BRDF factor, referenced to the s direction [1]."""
    rs, rp = fresnel_sp(cos_theta, eta)
    return np.asarray(0.5 * (rs - rp), dtype=float)


def _unit(v: F64) -> F64:
    norm = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.asarray(v / np.where(norm > 0, norm, 1.0))


def sky_axes(observer_dir: F64, pole: F64) -> tuple[F64, F64]:
    """North and east unit vectors (N, 3) on the sky of an observer, in the frame of the inputs.

    ``observer_dir`` (N, 3): unit vectors from the target to the observer; ``pole`` (N, 3):
    the celestial (GCRS) z axis in the same frame. A target at the pole has no north: its
    rows are NaN.
    """
    d = -np.asarray(observer_dir, dtype=float)  # line of sight, observer -> target
    east = np.cross(pole, d)
    ok = np.linalg.norm(east, axis=1) > 1e-12
    east = np.where(ok[:, None], _unit(east), np.nan)
    north = np.cross(d, east)
    return north, east


def scattering_angle_on_sky(sun_dir: F64, observer_dir: F64, pole: F64) -> F64:
    """Position angle chi [rad] (N,) of the normal to the scattering plane, from north
    through east: the direction of s-polarised reflected light on the sky.

    Where the Sun and observer directions are parallel (no scattering plane) chi is 0; the
    linear polarisation of single scattering vanishes there anyway (normal incidence).
    """
    north, east = sky_axes(observer_dir, pole)
    perp = np.cross(sun_dir, observer_dir)
    ok = np.linalg.norm(perp, axis=1) > 1e-12
    perp = np.where(ok[:, None], _unit(perp), north)
    chi = np.arctan2(np.einsum("nk,nk->n", perp, east), np.einsum("nk,nk->n", perp, north))
    return np.asarray(chi)


def rotate_linear(q: F64, u: F64, chi: ArrayLike) -> tuple[F64, F64]:
    """Stokes ``(Q, U)`` referenced to a direction at position angle ``chi`` [rad], expressed
    in the frame of position angle 0: ``Q' = Q cos 2chi - U sin 2chi``,
    ``U' = Q sin 2chi + U cos 2chi`` (a linear polarisation at angle psi from the old
    reference is at psi + chi from the new one; Chandrasekhar, Radiative Transfer, 1950,
    sec. 15). ``chi`` broadcasts against the leading axes of ``q`` and ``u``."""
    c2 = np.cos(2.0 * np.asarray(chi, dtype=float))
    s2 = np.sin(2.0 * np.asarray(chi, dtype=float))
    while c2.ndim < np.ndim(q):
        c2, s2 = c2[..., None], s2[..., None]
    return q * c2 - u * s2, q * s2 + u * c2


def dolp_aolp(i: ArrayLike, q: ArrayLike, u: ArrayLike) -> tuple[F64, F64]:
    """Degree [1] and angle [deg, in [0, 180)] of linear polarisation from Stokes I, Q, U.

    ``dolp = sqrt(Q^2 + U^2) / I`` (NaN where I is not positive), ``aolp = atan2(U, Q) / 2``
    counted from the frame's reference direction (north) through east; NaN where the light
    is unpolarised (Q = U = 0) or I is not positive.
    """
    i, q, u = (np.asarray(x, dtype=float) for x in (i, q, u))
    with np.errstate(divide="ignore", invalid="ignore"):
        dolp = np.where(i > 0, np.hypot(q, u) / np.where(i > 0, i, 1.0), np.nan)
    aolp = np.mod(0.5 * np.degrees(np.arctan2(u, q)), 180.0)
    aolp = np.where(np.isfinite(dolp) & (np.hypot(q, u) > 0), aolp, np.nan)
    return np.asarray(dolp), np.asarray(aolp)


def check_polarizable(materials: Iterable[Material], mode: str = "single") -> None:
    """Raise an InputError naming the first material whose polarisation is not modelled in
    render mode ``mode`` (the models' ``polarized_modes``, :mod:`speclight.target.bsdf_models`).

    Measured BRDFs (lab tables and RGL ``.bsdf`` files) are unpolarised measurements of
    intensity: treating them as unpolarising would claim a DoLP of 0 for surfaces that can
    polarise strongly (glass, paint), so ``render.polarization`` refuses them. Path mode
    also refuses ``plastic`` (its coat is a Python BSDF without a Mueller matrix).
    """
    accepted = ", ".join(dict.fromkeys(f.name for f in BSDF_FORMS if mode in f.polarized_modes))
    for m in materials:
        if mode not in m.model.polarized_modes:
            raise InputError(
                f"material '{m.name}': bsdf '{m.bsdf}' has no polarisation model in "
                f"render.mode '{mode}' (render.polarization: true accepts "
                f"{accepted}); set render.polarization: false or change the bsdf",
                field=f"target.materials.{m.name}.bsdf",
            )
