"""Geometric parts of the BRDF models, written out in numpy.

Microfacet terms follow Walter, Marschner, Li & Torrance 2007, "Microfacet models for
refraction through rough surfaces", EGSR, doi:10.2312/EGWR/EGSR07/195-206 (eqs. 25-27 Beckmann,
33-34 GGX), with the separable Smith shadowing G = G1(i) G1(o) as Mitsuba 3 uses, so that the
single-scattering and path-traced renders share one model.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]


def microfacet_d(cos_h: F64, alpha: float, kind: Literal["beckmann", "ggx"]) -> F64:
    """Normal distribution D(h) [sr-1] for microfacet normals at ``cos_h`` from the normal."""
    c2 = np.clip(cos_h, 1e-12, 1.0) ** 2
    tan2 = (1.0 - c2) / c2
    a2 = alpha * alpha
    if kind == "beckmann":
        d = np.exp(-tan2 / a2) / (np.pi * a2 * c2 * c2)
    else:
        d = a2 / (np.pi * c2 * c2 * (a2 + tan2) ** 2)
    return np.where(cos_h > 0, d, 0.0)


def smith_g1(cos_v: F64, alpha: float, kind: Literal["beckmann", "ggx"]) -> F64:
    """Smith masking G1 for a direction at ``cos_v`` from the macro normal [1]."""
    c = np.clip(cos_v, 1e-12, 1.0)
    tan = np.sqrt(np.maximum(1.0 - c * c, 0.0)) / c
    if kind == "beckmann":
        a = 1.0 / np.maximum(alpha * tan, 1e-30)
        approx = (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a)
        g = np.where(a < 1.6, approx, 1.0)
    else:
        g = 2.0 / (1.0 + np.sqrt(1.0 + (alpha * tan) ** 2))
    return np.where(cos_v > 0, g, 0.0)


def microfacet_weight(
    cos_i: F64, cos_o: F64, cos_h: F64, alpha: float, kind: Literal["beckmann", "ggx"]
) -> F64:
    """``f cos_i / F`` of the Cook-Torrance model: D G / (4 cos_o) [sr-1]."""
    g = smith_g1(cos_i, alpha, kind) * smith_g1(cos_o, alpha, kind)
    return microfacet_d(cos_h, alpha, kind) * g / (4.0 * np.clip(cos_o, 1e-12, None))
