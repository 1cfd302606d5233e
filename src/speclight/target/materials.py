"""Surface materials: a BRDF model and its spectral reflectance."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, get_args

from speclight.errors import InputError, did_you_mean
from speclight.target.reflectance import Reflectance
from speclight.target.rgl_file import check_rgl_material, is_rgl_path

BsdfName = Literal["lambertian", "beckmann", "ggx", "plastic", "specular", "measured"]
BSDF_NAMES: tuple[str, ...] = get_args(BsdfName)
#: Largest accepted microfacet roughness alpha (RMS slope); beyond ~1 the models lose meaning.
MAX_ROUGHNESS = 1.0


@dataclass(frozen=True)
class Material:
    """A surface material.

    Parameters
    ----------
    name
        Label used in messages and outputs.
    bsdf
        ``lambertian`` (ideal diffuse), ``beckmann`` / ``ggx`` (rough surface, Cook-Torrance
        microfacet model with that normal distribution, Walter et al. 2007,
        doi:10.2312/EGWR/EGSR07/195-206), ``specular`` (smooth mirror), ``plastic`` (diffuse
        base under a dielectric coat: smooth, or Beckmann-rough when ``roughness`` is given) or
        ``measured`` (tabulated BRDF, see :mod:`speclight.target.brdf_table`).
    reflectance
        Spectral reflectance: the albedo of a Lambertian surface, the Fresnel term of the
        microfacet and mirror models (angle dependent for n,k kinds).
    roughness
        Microfacet alpha (RMS slope for Beckmann) for ``beckmann`` / ``ggx``, in (0, 1].
    diffuse_reflectance
        Base albedo of ``plastic`` (its ``reflectance`` must be the coat's dielectric n, k).
    brdf_table
        Shipped table name or path of the measured BRDF table for ``measured``; its
        ``reflectance`` scales it by ``R(lambda) / R(table wavelength)`` (1 for a constant).
        A path ending in ``.bsdf`` is an RGL measured material (Mitsuba's ``measured``
        plugin, :mod:`speclight.target.rgl_file`): isotropic files only, checked on creation;
        its ``reflectance`` must be a constant scale factor in (0, 1] (1: as measured).
    """

    name: str
    bsdf: BsdfName
    reflectance: Reflectance
    roughness: float | None = None
    diffuse_reflectance: Reflectance | None = None
    brdf_table: str | None = None

    def __post_init__(self) -> None:
        field = f"materials.{self.name}"
        if self.bsdf not in BSDF_NAMES:
            raise InputError(
                f"unknown bsdf '{self.bsdf}'{did_you_mean(self.bsdf, BSDF_NAMES)} "
                f"(choices: {', '.join(BSDF_NAMES)})",
                field=f"{field}.bsdf",
            )
        if not isinstance(self.reflectance, Reflectance):
            raise InputError(
                "reflectance must be a speclight.target.Reflectance", field=f"{field}.reflectance"
            )
        if self.bsdf in ("beckmann", "ggx"):
            r = self.roughness
            if r is None or not 0.0 < float(r) <= MAX_ROUGHNESS:
                raise InputError(
                    f"roughness = {r!r} must be given for bsdf '{self.bsdf}' and lie in "
                    f"(0, {MAX_ROUGHNESS:g}] (microfacet alpha; use 'specular' for a mirror)",
                    field=f"{field}.roughness",
                )
        elif self.roughness is not None and self.bsdf != "plastic":
            raise InputError(
                f"roughness is not used by bsdf '{self.bsdf}'; remove it or use beckmann/ggx",
                field=f"{field}.roughness",
            )
        if self.bsdf == "plastic":
            if self.diffuse_reflectance is None:
                raise InputError(
                    "bsdf 'plastic' needs diffuse_reflectance (the base under the coat)",
                    field=f"{field}.diffuse_reflectance",
                )
            if self.reflectance.kind != "dielectric":
                raise InputError(
                    "bsdf 'plastic' needs reflectance: {dielectric: NAME} (the coat's n, k), "
                    f"got a {self.reflectance.kind} reflectance",
                    field=f"{field}.reflectance",
                )
            r = self.roughness
            if r is not None and not 0.0 < float(r) <= MAX_ROUGHNESS:
                raise InputError(
                    f"roughness = {r!r} must lie in (0, {MAX_ROUGHNESS:g}] (coat microfacet "
                    "alpha) or be omitted for a smooth coat",
                    field=f"{field}.roughness",
                )
        if self.bsdf == "measured" and not self.brdf_table:
            raise InputError(
                "bsdf 'measured' needs brdf_table (a BRDF table file)",
                field=f"{field}.brdf_table",
            )
        if self.bsdf == "measured" and is_rgl_path(self.brdf_table):
            check_rgl_material(str(self.brdf_table), self.reflectance, field)
