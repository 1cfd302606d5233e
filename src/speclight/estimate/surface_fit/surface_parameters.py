"""The free parameters of the analytic BRDF models in ``speclight fit --free brdf``.

Each analytic model (:data:`speclight.target.brdf_fit.form_coefficients.FORMS`) frees the
coefficients listed in :data:`FREE_COEFFICIENTS`, each fitted in log10 (positive
quantities spanning decades: Phong's kd, ks and n, ABg's A and B, the microfacet's diffuse
albedo, F0 and roughness) or as is (ABg's slope g; the binomial's ``b[0][0]``, the log10 of
its overall factor, whose shape coefficients stay as given: twelve coefficients per surface
are more than magnitudes of a few passes can separate). The bounds are those of the
coefficients' own checks, narrowed to values that such surfaces take (e.g. a Phong
exponent in [0.1, 1e4]).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.target.brdf_fit.form_coefficients import FORMS

F64 = NDArray[np.float64]


@dataclass(frozen=True)
class FreeCoefficient:
    """One fitted coefficient: its key, whether it is fitted in log10, and its bounds."""

    name: str
    log10: bool
    low: float
    high: float

    def to_fit(self, value: float) -> float:
        """The coefficient's value [its unit] as the fit's variable, clipped to the bounds."""
        v = float(np.clip(value, self.low, self.high))
        return float(np.log10(v)) if self.log10 else v

    def from_fit(self, u: float) -> float:
        """The fit's variable back to the coefficient's value."""
        return float(10.0**u) if self.log10 else float(u)

    @property
    def bounds(self) -> tuple[float, float]:
        """The bounds of the fit's variable."""
        return (self.to_fit(self.low), self.to_fit(self.high))


#: The coefficients that ``--free brdf`` fits, per analytic model.
FREE_COEFFICIENTS: Mapping[str, tuple[FreeCoefficient, ...]] = MappingProxyType(
    {
        "phong": (
            FreeCoefficient("kd", True, 1e-4, 1.0),
            FreeCoefficient("ks", True, 1e-4, 1.0),
            FreeCoefficient("n", True, 0.1, 1e4),
        ),
        "abg": (
            FreeCoefficient("a", True, 1e-10, 1e4),
            FreeCoefficient("b", True, 1e-10, 1e2),
            FreeCoefficient("g", False, 0.05, 10.0),
        ),
        "microfacet": (
            FreeCoefficient("diffuse", True, 1e-4, 1.0),
            FreeCoefficient("f0", True, 1e-4, 1.0),
            FreeCoefficient("roughness", True, 5e-3, 1.0),
        ),
        "binomial": (FreeCoefficient("b00", False, -20.0, 20.0),),
    }
)


def coefficient_value(coefficients: Mapping[str, Any], name: str) -> float:
    """The value of free coefficient ``name`` (``b00``: the binomial's ``b[0][0]``)."""
    if name == "b00":
        return float(coefficients["b"][0][0])
    return float(coefficients[name])


def with_values(coefficients: Mapping[str, Any], values: Mapping[str, float]) -> dict[str, Any]:
    """A copy of ``coefficients`` with the free coefficients set to ``values``."""
    out = {
        k: (np.asarray(v, dtype=float).tolist() if k in "bc" else v)
        for k, v in coefficients.items()
    }
    for name, v in values.items():
        if name == "b00":
            out["b"][0][0] = float(v)
        else:
            out[name] = float(v)
    return out


@dataclass(frozen=True)
class FreeSurface:
    """A material whose analytic BRDF is fitted: its key, model and starting coefficients."""

    name: str
    bsdf: str
    start: Mapping[str, Any]

    @property
    def free(self) -> tuple[FreeCoefficient, ...]:
        return FREE_COEFFICIENTS[self.bsdf]

    def start_vector(self) -> F64:
        """The fit's variables at the start (clipped into the bounds)."""
        return np.array([c.to_fit(coefficient_value(self.start, c.name)) for c in self.free])

    def coefficients(self, u: F64) -> dict[str, Any]:
        """The material's coefficients for the fit's variables ``u``."""
        values = {c.name: c.from_fit(float(x)) for c, x in zip(self.free, u, strict=True)}
        return with_values(FORMS[self.bsdf].complete(self.start), values)


def free_surfaces(
    materials: Mapping[str, Any], names: list[str] | None = None
) -> list[FreeSurface]:
    """The scenario's analytic materials to fit (``names``: those only; None: every one).

    ``materials`` maps a material key to its scenario model (``bsdf``, ``coefficients``,
    ``reflectance``). Their reflectance must be a constant: the fit holds every surface
    grey (the model's magnitude is then exact, :mod:`.surface_model`).
    """
    analytic = {k: m for k, m in materials.items() if m.bsdf in FREE_COEFFICIENTS}
    chosen = list(analytic) if names is None else list(names)
    if not chosen:
        raise InputError(
            "no material of the target has an analytic BRDF to fit (bsdf: "
            f"{', '.join(FREE_COEFFICIENTS)}); materials: "
            + ", ".join(f"{k} ({m.bsdf})" for k, m in materials.items()),
            field="target.materials",
        )
    out = []
    for name in chosen:
        if name not in analytic:
            raise InputError(
                f"materials = {name!r} is not an analytic material of the target (those: "
                f"{', '.join(analytic) or 'none'})",
                field="materials",
            )
        m = analytic[name]
        if not isinstance(m.reflectance, int | float):
            raise InputError(
                f"target.materials.{name}.reflectance must be a number for a BRDF fit (the "
                "fit holds each surface grey); got a spectrum",
                field="target.materials",
            )
        out.append(FreeSurface(name, m.bsdf, dict(m.coefficients)))
    return out
