"""Scattering laws of a facet: its brightness per unit area and their derivatives.

A facet of area ``A`` with normal ``n``, lit from ``s`` and seen from ``o`` (unit vectors,
``mu0 = n . s > 0``, ``mu = n . o > 0``), sends the radiant intensity ``A S(mu0, mu) E``
toward the observer under the irradiance ``E``: ``S`` [sr-1] is the bidirectional
reflectance times ``mu0 mu``. Every law here is a function of ``mu0``, ``mu`` and the
epoch's half-phase cosine ``cos(alpha / 2)`` (the half vector's cosine with the facet normal
is ``(mu0 + mu) / (2 cos(alpha / 2))``), and returns ``S`` with ``dS/dmu0`` and ``dS/dmu``.

The asteroid laws (Kaasalainen, Torppa & Muinonen 2001, Icarus 153, 37, eq. 2 and sec. 2.2,
doi:10.1006/icar.2001.6674):

* ``lambert``: ``S = mu0 mu / pi`` (a white Lambertian surface);
* ``lommel-seeliger``: ``S = mu0 mu / (mu0 + mu) / (4 pi)`` (single scattering, albedo 1);
* ``ls-lambert``: convexinv's combination ``S = mu0 mu (1 / (mu0 + mu) + c) / (4 pi)`` with the
  Lambert weight ``c`` (0.1 by default, as convexinv).

For satellites, ``material``: one of speclight's own BRDF models (``lambertian``,
``beckmann``, ``ggx``, ``measured``, and the analytic ``phong``, ``abg``, ``binomial``,
``microfacet``) through the render stage's material evaluation
(:meth:`speclight.render.bsdfs.MaterialBsdf.fcos`: every channel, as the single-scattering
render sums them per pixel), at one wavelength; its derivatives
by central differences of step :data:`MATERIAL_STEP` (the microfacet lobes have no
closed-form derivative in the cosines here).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError, did_you_mean
from speclight.target.materials import Material

F64 = NDArray[np.float64]
LAW_NAMES = ("lambert", "lommel-seeliger", "ls-lambert")
MATERIAL_BSDFS = (
    "lambertian",
    "beckmann",
    "ggx",
    "measured",
    "phong",
    "abg",
    "binomial",
    "microfacet",
)
#: Step of the central differences of a material law in mu0 and mu [1].
MATERIAL_STEP = 1e-5
#: A floor of ``mu0 + mu`` in the Lommel-Seeliger term, whose numerator is then 0 [1].
_TINY_SUM = 1e-300
#: convexinv's Lambert weight of the ``ls-lambert`` law.
DEFAULT_LAMBERT_WEIGHT = 0.1


class ScatteringLaw(Protocol):
    """A facet law: ``law(mu0, mu, cos_half_phase) -> (S, dS/dmu0, dS/dmu)`` (module doc)."""

    @property
    def name(self) -> str:
        """The law's name."""
        ...

    def __call__(self, mu0: F64, mu: F64, cos_half_phase: F64) -> tuple[F64, F64, F64]: ...


@dataclass(frozen=True)
class Lambert:
    """``S = mu0 mu / pi``."""

    name: str = "lambert"

    def __call__(self, mu0: F64, mu: F64, cos_half_phase: F64) -> tuple[F64, F64, F64]:
        return mu0 * mu / np.pi, mu / np.pi, mu0 / np.pi


@dataclass(frozen=True)
class LommelSeeligerLambert:
    """``S = mu0 mu (1 / (mu0 + mu) + c) / (4 pi)``; ``c = 0`` is pure Lommel-Seeliger."""

    lambert_weight: float = DEFAULT_LAMBERT_WEIGHT
    name: str = "ls-lambert"

    def __call__(self, mu0: F64, mu: F64, cos_half_phase: F64) -> tuple[F64, F64, F64]:
        # written in place: these arrays are (points x facets), the inversion's main cost
        c, k = self.lambert_weight, 1.0 / (4.0 * np.pi)
        work = np.add(mu0, mu)
        # 1 / (mu0 + mu), finite where both are 0 (a facet not lit and seen: S = S' = 0)
        inv = np.divide(1.0, np.maximum(work, _TINY_SUM, out=work))
        q = np.multiply(mu, inv)  # mu / (mu0 + mu)
        np.multiply(mu0, inv, out=inv)  # mu0 / (mu0 + mu)
        s = np.multiply(mu, c)
        s += q
        s *= mu0
        s *= k  # k mu0 mu (1 / (mu0 + mu) + c)
        d0 = np.multiply(q, q, out=q)
        d0 += np.multiply(mu, c, out=work)
        d0 *= k  # k (mu^2 / (mu0 + mu)^2 + c mu)
        d1 = np.multiply(inv, inv, out=inv)
        d1 += np.multiply(mu0, c, out=work)
        d1 *= k
        return s, d0, d1


@dataclass(frozen=True)
class MaterialLaw:
    """A speclight material at ``wavelength_nm`` (module doc)."""

    material: Material
    wavelength_nm: float
    name: str = "material"

    def value(self, mu0: F64, mu: F64, cos_half_phase: F64) -> F64:
        """``S`` alone (the law without derivatives)."""
        from speclight.render.bsdfs import material_bsdf

        bsdf = material_bsdf(self.material)
        mu0, mu, chp = np.broadcast_arrays(mu0, mu, cos_half_phase)
        chp_safe = np.where(chp > 1e-9, chp, 1e-9)
        cos_h = np.clip((mu0 + mu) / (2.0 * chp_safe), -1.0, 1.0)
        flat = [np.ravel(x) for x in (mu0, mu, cos_h, chp)]
        # every channel (a lab table's extension is a block channel beside its main one)
        wl = np.array([self.wavelength_nm])
        fcos = bsdf.fcos(flat[0], flat[1], flat[2], flat[3], np.zeros_like(flat[0]), wl)[:, 0]
        lit = (flat[0] > 0) & (flat[1] > 0)
        return np.where(lit, flat[1] * fcos, 0.0).reshape(mu0.shape)

    def __call__(self, mu0: F64, mu: F64, cos_half_phase: F64) -> tuple[F64, F64, F64]:
        h = MATERIAL_STEP
        s = self.value(mu0, mu, cos_half_phase)
        d0 = (self.value(mu0 + h, mu, cos_half_phase) - self.value(mu0 - h, mu, cos_half_phase)) / (
            2 * h
        )
        d1 = (self.value(mu0, mu + h, cos_half_phase) - self.value(mu0, mu - h, cos_half_phase)) / (
            2 * h
        )
        return s, d0, d1


def scattering_law(
    name: str,
    *,
    lambert_weight: float = DEFAULT_LAMBERT_WEIGHT,
    material: Material | None = None,
    wavelength_nm: float = 550.0,
) -> ScatteringLaw:
    """The law called ``name``: one of :data:`LAW_NAMES`, or ``"material"`` with ``material``.

    Raises
    ------
    InputError
        For an unknown name (field ``law``), a negative ``lambert_weight`` or a material
        whose BSDF has no facet law (accepted: :data:`MATERIAL_BSDFS`).
    """
    if name == "lambert":
        return Lambert()
    if name in ("lommel-seeliger", "ls-lambert"):
        if not (np.isfinite(lambert_weight) and lambert_weight >= 0):
            raise InputError(
                f"lambert_weight = {lambert_weight} must be >= 0", field="lambert_weight"
            )
        return LommelSeeligerLambert(
            0.0 if name == "lommel-seeliger" else lambert_weight, name=name
        )
    if name == "material" and material is not None:
        if material.bsdf not in MATERIAL_BSDFS or (
            material.brdf_table is not None and str(material.brdf_table).endswith(".bsdf")
        ):
            raise InputError(
                f"material '{material.name}' has bsdf '{material.bsdf}', which has no facet "
                f"law here (accepted: {', '.join(MATERIAL_BSDFS)}; RGL .bsdf files excluded)",
                field="law",
            )
        return MaterialLaw(material, float(wavelength_nm))
    raise InputError(
        f"unknown scattering law '{name}'{did_you_mean(name, LAW_NAMES)} (choices: "
        f"{', '.join(LAW_NAMES)}, or material:NAME with a scenario)",
        field="law",
    )
