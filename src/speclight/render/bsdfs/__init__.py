"""The render side of the BSDF models: one module per model, one table of them.

:data:`RENDERERS` maps each model (each form of a model, by its label in
:data:`speclight.target.bsdf_models.BSDF_FORMS`) to the :class:`MaterialBsdf` subclass that
evaluates it (single-mode channels, polarisation factors, the path-mode Mitsuba BSDF,
roughness derivatives). A test checks that every registered model has one.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from types import MappingProxyType
from typing import Any

from speclight.errors import InputError
from speclight.render.bsdfs.bsdf_analytic import AnalyticBsdf
from speclight.render.bsdfs.bsdf_interface import MaterialBsdf
from speclight.render.bsdfs.bsdf_lambertian import LambertianBsdf
from speclight.render.bsdfs.bsdf_measured import MeasuredRglBsdf, MeasuredTableBsdf
from speclight.render.bsdfs.bsdf_microfacet import MicrofacetBsdf
from speclight.render.bsdfs.bsdf_plastic import PlasticBsdf
from speclight.render.bsdfs.bsdf_specular import SpecularBsdf
from speclight.target.bsdf_models import BSDF_FORMS, MEASURED_RGL, MEASURED_TABLE
from speclight.target.materials import Material

#: The evaluator of every model (form), by its label.
RENDERERS: Mapping[str, type[MaterialBsdf]] = MappingProxyType(
    {
        "lambertian": LambertianBsdf,
        "beckmann": MicrofacetBsdf,
        "ggx": MicrofacetBsdf,
        "plastic": PlasticBsdf,
        "specular": SpecularBsdf,
        MEASURED_TABLE.label: MeasuredTableBsdf,
        MEASURED_RGL.label: MeasuredRglBsdf,
        "phong": AnalyticBsdf,
        "abg": AnalyticBsdf,
        "binomial": AnalyticBsdf,
        "microfacet": AnalyticBsdf,
    }
)


def material_bsdf(m: Material, mode: str | None = None) -> MaterialBsdf:
    """The evaluator of material ``m`` in render mode ``mode`` (``single``, ``path``; None:
    any mode, for what every mode shares).

    Raises
    ------
    InputError
        The material's model does not support ``mode`` (the message lists the models that do).
    """
    model = m.model
    if mode is not None and mode not in model.modes:
        accepted = ", ".join(f.label for f in BSDF_FORMS if mode in f.modes)
        raise InputError(
            f"material '{m.name}': bsdf '{model.label}' is not supported in render.mode "
            f"'{mode}' (it supports {', '.join(model.modes)}; '{mode}' supports {accepted})",
            field="render.mode",
        )
    return RENDERERS[model.label](m)


def planned_channels(m: Any, resolve: Callable[[str], Path] | None = None) -> int:
    """Single-mode channels of a scenario material (:class:`speclight.scenario.Material`,
    not built yet): its main channel and its block (see
    :meth:`MaterialBsdf.planned_block_size`)."""
    return 1 + RENDERERS[m.model.label].planned_block_size(m.parameters(), resolve)


__all__ = ["RENDERERS", "MaterialBsdf", "material_bsdf", "planned_channels"]
