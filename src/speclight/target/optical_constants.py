"""Shipped complex refractive indices n + i k and the Fresnel reflectance they give.

Tables (refractiveindex.info database, CC0; see ``data/optical_constants/PROVENANCE.md``):
Al (Rakić 1995, doi:10.1364/AO.34.004755), Ag and Au (Johnson & Christy 1972,
doi:10.1103/PhysRevB.6.4370), Si (Green 2008, doi:10.1016/j.solmat.2008.06.009), GaAs
(Aspnes et al. 1986, doi:10.1063/1.337426), Kapton (Arakawa et al. 1981,
doi:10.1063/1.329140), SiO2 (Malitson 1965 Sellmeier formula, doi:10.1364/JOSA.55.001205).
"""

from __future__ import annotations

from functools import cache
from importlib import resources
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError, did_you_mean

CONDUCTORS: tuple[str, ...] = ("Al", "Ag", "Au")
DIELECTRICS: tuple[str, ...] = ("SiO2", "Si", "GaAs", "Kapton")


@cache
def _table(name: str) -> NDArray[np.float64]:
    path = resources.files("speclight").joinpath("data", "optical_constants", f"{name}.csv")
    return np.loadtxt(path.read_text().splitlines(), delimiter=",", comments="#", skiprows=2)


def check_nk_name(name: str, kind: Literal["conductor", "dielectric"]) -> None:
    """Raise :class:`InputError` unless ``name`` is a shipped ``kind`` material."""
    choices = CONDUCTORS if kind == "conductor" else DIELECTRICS
    if name not in choices:
        other = DIELECTRICS if kind == "conductor" else CONDUCTORS
        hint = f"; '{name}' is listed as the other kind" if name in other else ""
        raise InputError(
            f"unknown {kind} '{name}'{did_you_mean(name, choices) or hint} "
            f"(choices: {', '.join(choices)})",
            field=kind,
        )


def refractive_index(name: str, wavelength_nm: ArrayLike) -> NDArray[np.complex128]:
    """Complex refractive index ``n + i k`` of a shipped material, linearly interpolated.

    Parameters
    ----------
    name
        One of :data:`CONDUCTORS` or :data:`DIELECTRICS`.
    wavelength_nm
        Wavelengths [nm]; must lie inside the table.
    """
    if name not in CONDUCTORS + DIELECTRICS:
        check_nk_name(name, "conductor")
    t = _table(name)
    wl = np.asarray(wavelength_nm, dtype=float)
    if np.any(wl < t[0, 0]) or np.any(wl > t[-1, 0]):
        raise InputError(
            f"n,k table of {name} covers {t[0, 0]:g}-{t[-1, 0]:g} nm, the wavelength grid "
            f"reaches {np.min(wl):g}-{np.max(wl):g} nm; narrow the spectrum or give a table",
            field="reflectance",
        )
    return np.interp(wl, t[:, 0], t[:, 1]) + 1j * np.interp(wl, t[:, 0], t[:, 2])


def fresnel_reflectance(cos_theta: ArrayLike, eta: ArrayLike) -> NDArray[np.float64]:
    """Unpolarised Fresnel reflectance of a vacuum / (n + i k) interface.

    Parameters
    ----------
    cos_theta
        Cosine of the angle of incidence (..., 1) or broadcastable [1], in [0, 1].
    eta
        Complex refractive index ``n + i k`` broadcastable against ``cos_theta`` [1].

    Returns
    -------
    numpy.ndarray
        ``(|r_s|^2 + |r_p|^2) / 2`` (Born & Wolf, Principles of Optics, 7th ed., sec. 1.5 and
        14.2; complex Snell's law with ``cos_t = sqrt(1 - sin^2 / eta^2)``).
    """
    c = np.clip(np.asarray(cos_theta, dtype=float), 0.0, 1.0)
    n = np.asarray(eta, dtype=complex)
    cos_t = np.sqrt(1.0 - (1.0 - c * c) / (n * n))
    r_s = (c - n * cos_t) / (c + n * cos_t)
    r_p = (n * c - cos_t) / (n * c + cos_t)
    return np.asarray(0.5 * (np.abs(r_s) ** 2 + np.abs(r_p) ** 2), dtype=float)
