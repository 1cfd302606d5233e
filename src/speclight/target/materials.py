"""Surface materials: a BRDF model and its spectral reflectance."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from speclight.errors import InputError
from speclight.target.brdf_fit.form_coefficients import FrozenCoefficients
from speclight.target.bsdf_models import (
    BSDF_NAMES,
    MAX_ROUGHNESS,
    PARAMETERS,
    BsdfModel,
    BsdfName,
    bsdf_model,
    check_bsdf_name,
    parameter_problems,
)
from speclight.target.reflectance import Reflectance

__all__ = ["BSDF_NAMES", "MAX_ROUGHNESS", "BsdfName", "Material"]


@dataclass(frozen=True)
class Material:
    """A surface material.

    Parameters
    ----------
    name
        Label used in messages and outputs.
    bsdf
        A name of :data:`~speclight.target.bsdf_models.BSDF_MODELS` (the table that also says
        which parameters each takes): ``lambertian`` (ideal diffuse), ``beckmann`` / ``ggx``
        (rough surface, Cook-Torrance microfacet model with that normal distribution,
        Walter et al. 2007,
        doi:10.2312/EGWR/EGSR07/195-206), ``specular`` (smooth mirror), ``plastic`` (diffuse
        base under a dielectric coat: smooth, or Beckmann-rough when ``roughness`` is given),
        ``measured`` (tabulated BRDF, see :mod:`speclight.target.brdf_table`), or an analytic
        model fitted to a table, ``phong``, ``abg``, ``binomial``, ``microfacet``
        (:mod:`speclight.target.brdf_fit`, docs/brdf-models.md).
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
    extension
        ``measured`` lab tables: the analytic model fitted to the table that holds outside
        its measured support (:data:`speclight.target.brdf_table.EXTENSIONS`; None: the
        default, :data:`~speclight.target.brdf_table.DEFAULT_EXTENSION`).
    coefficients
        The analytic models' coefficients (a mapping, e.g. ``{"kd": 0.1, "ks": 0.4, "n":
        30}``; :mod:`speclight.target.brdf_fit.form_coefficients`); their ``reflectance``
        scales them by ``R(lambda) / R(coefficients["wavelength_nm"])`` (1 for a constant).
    """

    name: str
    bsdf: BsdfName
    reflectance: Reflectance
    roughness: float | None = None
    diffuse_reflectance: Reflectance | None = None
    brdf_table: str | None = None
    extension: str | None = None
    coefficients: Mapping[str, Any] | None = None

    def __post_init__(self) -> None:
        field = f"target.materials.{self.name}"
        check_bsdf_name(self.bsdf, f"{field}.bsdf")
        if not isinstance(self.reflectance, Reflectance):
            raise InputError(
                "reflectance must be a speclight.target.Reflectance", field=f"{field}.reflectance"
            )
        given = self.parameters()
        problems = parameter_problems(self.bsdf, given, self.reflectance.kind)
        if problems:
            key, message = problems[0]
            raise InputError(message, field=f"{field}.{key}")
        if isinstance(self.coefficients, Mapping):  # checked: now an immutable copy
            object.__setattr__(self, "coefficients", FrozenCoefficients(self.coefficients))
        check = self.model.check
        if check is not None:  # reads the material's file (an RGL .bsdf)
            check(self, field)

    @property
    def model(self) -> BsdfModel:
        """The material's entry (its form) in the table of BSDF models."""
        return bsdf_model(self.bsdf, self.parameters())

    def parameters(self) -> dict[str, object]:
        """The model parameters given (:data:`speclight.target.bsdf_models.PARAMETERS`)."""
        return {name: getattr(self, name) for name in PARAMETERS}
