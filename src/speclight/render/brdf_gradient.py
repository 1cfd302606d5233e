"""Roughness derivatives of the microfacet terms of :mod:`speclight.target.microfacet_terms`,
analytic.

Same formulas, same clipping (Walter, Marschner, Li & Torrance 2007, EGSR,
doi:10.2312/EGWR/EGSR07/195-206; t = tan^2 of the angle to the normal, ``a`` the roughness):

* Beckmann ``D = exp(-t/a^2) / (pi a^2 cos^4)``: ``dD/da = D (2 t / a^3 - 2 / a)``;
* GGX ``D = a^2 / (pi cos^4 (a^2 + t)^2)``: ``dD/da = D (2 / a - 4 a / (a^2 + t))``;
* Beckmann Smith ``G1 = g(b)``, ``b = 1 / (a tan)``, ``g`` Walter's rational fit (1 for
  b >= 1.6): ``dG1/da = g'(b) (-b / a)`` with
  ``g'(b) = (P' Q - P Q') / Q^2``, ``P = 3.535 b + 2.181 b^2``, ``Q = 1 + 2.276 b + 2.577 b^2``;
* GGX Smith ``G1 = 2 / (1 + s)``, ``s = sqrt(1 + a^2 tan^2)``:
  ``dG1/da = -2 a tan^2 / (s (1 + s)^2)``;
* the weight ``D G1(i) G1(o) / (4 cos_o)`` by the product rule.

The rational fit's derivative jumps at b = 1.6 (the fit is continuous there, to 1e-5, its
slope is not): a kink of the model itself, not of this derivative.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.typing import NDArray

from speclight.target.microfacet_terms import microfacet_d, smith_g1

F64 = NDArray[np.float64]
Kind = Literal["beckmann", "ggx"]


def microfacet_d_dalpha(cos_h: F64, alpha: float, kind: Kind) -> F64:
    """dD/dalpha [sr-1] of :func:`~speclight.target.microfacet_terms.microfacet_d` (module doc)."""
    c2 = np.clip(cos_h, 1e-12, 1.0) ** 2
    tan2 = (1.0 - c2) / c2
    d = microfacet_d(cos_h, alpha, kind)
    if kind == "beckmann":
        return d * (2.0 * tan2 / alpha**3 - 2.0 / alpha)
    return d * (2.0 / alpha - 4.0 * alpha / (alpha * alpha + tan2))


def smith_g1_dalpha(cos_v: F64, alpha: float, kind: Kind) -> F64:
    """dG1/dalpha [1] of :func:`~speclight.target.microfacet_terms.smith_g1` (module doc)."""
    c = np.clip(cos_v, 1e-12, 1.0)
    tan = np.sqrt(np.maximum(1.0 - c * c, 0.0)) / c
    if kind == "beckmann":
        b = 1.0 / np.maximum(alpha * tan, 1e-30)
        p, dp = 3.535 * b + 2.181 * b * b, 3.535 + 4.362 * b
        q, dq = 1.0 + 2.276 * b + 2.577 * b * b, 2.276 + 5.154 * b
        dg_db = (dp * q - p * dq) / (q * q)
        dg = np.where(b < 1.6, dg_db * (-b / alpha), 0.0)
    else:
        s = np.sqrt(1.0 + (alpha * tan) ** 2)
        dg = -2.0 * alpha * tan * tan / (s * (1.0 + s) ** 2)
    return np.where(cos_v > 0, dg, 0.0)


def microfacet_weight_dalpha(cos_i: F64, cos_o: F64, cos_h: F64, alpha: float, kind: Kind) -> F64:
    """d/dalpha of :func:`~speclight.target.microfacet_terms.microfacet_weight` [sr-1]."""
    gi, go = smith_g1(cos_i, alpha, kind), smith_g1(cos_o, alpha, kind)
    dgi, dgo = smith_g1_dalpha(cos_i, alpha, kind), smith_g1_dalpha(cos_o, alpha, kind)
    d, dd = microfacet_d(cos_h, alpha, kind), microfacet_d_dalpha(cos_h, alpha, kind)
    return (dd * gi * go + d * (dgi * go + gi * dgo)) / (4.0 * np.clip(cos_o, 1e-12, None))


__all__ = ["microfacet_d_dalpha", "microfacet_weight_dalpha", "smith_g1_dalpha"]
