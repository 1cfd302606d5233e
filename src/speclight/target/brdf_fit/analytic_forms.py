"""Analytic BRDF forms as plain numpy functions of the shading cosines.

Every form is a function ``f(cos_i, cos_o, cos_h, cos_d, coefficients)`` [sr-1] of the cosines
that the renders compute per pixel (:mod:`speclight.render.shading`): of the light and view
directions with the normal (``cos_i``, ``cos_o``), of the half vector with the normal
(``cos_h``) and of the light with the half vector (``cos_d``), for ``cos_i, cos_o > 0``. The
single mode, path mode (:mod:`speclight.render.bsdfs.path_analytic`) and ``speclight
brdf-fit`` all evaluate these functions, so a fitted material renders as it was fitted.

The quantities of lumos-sat's definitions (Fankhauser, Askari & Tyson 2023,
doi:10.48550/arXiv.2305.11123; package ``lumos-sat``, ``lumos/brdf/library.py``), written in
these cosines (with i, o the unit vectors toward the light and the observer, n the normal):

* the mirror direction of the light r = 2 (i.n) n - i, so
  ``r.o = 2 cos_i cos_o - i.o`` with ``i.o = 2 cos_d^2 - 1``;
* the distance of the projections of o and r on the surface plane (Harvey's
  ``|beta - beta_0|``): ``|o_t + i_t| = 2 cos_d sin(theta_h)``, since
  ``|i + o| = 2 cos_d`` and ``(i + o).n = 2 cos_d cos_h``;
* their dot product ``V = beta . beta_0 = cos_i cos_o - i.o``.

Each of these is symmetric in i and o: every form is reciprocal.

The forms take the array functions they use as ``ops`` (:class:`ArrayOps`): numpy's here,
Dr.Jit's in path mode, so that one written form serves both.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]


class ArrayOps:
    """The array functions the forms use, numpy's; path mode passes Dr.Jit's."""

    @staticmethod
    def sqrt(x: Any) -> Any:
        return np.sqrt(x)

    @staticmethod
    def clip(x: Any, low: float, high: float) -> Any:
        return np.clip(x, low, high)

    @staticmethod
    def maximum(x: Any, y: Any) -> Any:
        return np.maximum(x, y)

    @staticmethod
    def minimum(x: Any, y: Any) -> Any:
        return np.minimum(x, y)

    @staticmethod
    def log10(x: Any) -> Any:
        return np.log10(x)

    @staticmethod
    def power(x: Any, y: Any) -> Any:
        return np.power(x, y)

    @staticmethod
    def exp10(x: Any) -> Any:
        """``10^x``."""
        return np.power(10.0, x)

    @staticmethod
    def microfacet(cos_i: Any, cos_o: Any, cos_h: Any, alpha: float, kind: str) -> Any:
        """``D G1(i) G1(o) / (4 cos_i cos_o)`` [sr-1] (Walter et al. 2007; the terms of the
        ``ggx`` and ``beckmann`` models, :mod:`speclight.target.microfacet_terms`)."""
        from speclight.target.microfacet_terms import microfacet_weight  # one copy of the terms

        weight = microfacet_weight(cos_i, cos_o, cos_h, alpha, kind)  # type: ignore[arg-type]
        return weight / np.clip(cos_i, 1e-12, None)


NUMPY = ArrayOps()


def cos_light_view(cos_d: Any) -> Any:
    """``i.o``, the cosine of the angle between the light and view directions [1]."""
    return 2.0 * cos_d * cos_d - 1.0


def mirror_cosine(cos_i: Any, cos_o: Any, cos_d: Any) -> Any:
    """``r.o``: cosine between the view and the mirror direction of the light [1]."""
    return 2.0 * cos_i * cos_o - cos_light_view(cos_d)


def projected_distance(cos_h: Any, cos_d: Any, ops: ArrayOps = NUMPY) -> Any:
    """``|beta - beta_0| = 2 cos_d sin(theta_h)``: distance of the projections of the view
    and mirror directions on the surface plane [1] (Harvey 1976; Stover 2012, sec. 8.3)."""
    return 2.0 * cos_d * ops.sqrt(ops.maximum(1.0 - cos_h * cos_h, 0.0))


def phong(
    cos_i: Any, cos_o: Any, cos_h: Any, cos_d: Any, c: Mapping[str, Any], ops: ArrayOps = NUMPY
) -> Any:
    """Energy-normalised Phong: ``kd / pi + ks (n + 2) / (2 pi) max(r.o, 0)^n`` [sr-1].

    Lafortune & Willems 1994, "Using the modified Phong reflectance model for physically
    based rendering" (report CW 197, KU Leuven): the directional albedo is at most
    ``kd + ks``. lumos-sat's ``PHONG(Kd, Ks, n)``.
    """
    ro = ops.clip(mirror_cosine(cos_i, cos_o, cos_d), 0.0, 1.0)
    n = float(c["n"])
    return float(c["kd"]) / np.pi + float(c["ks"]) * (n + 2.0) / (2.0 * np.pi) * ops.power(ro, n)


def abg(
    cos_i: Any, cos_o: Any, cos_h: Any, cos_d: Any, c: Mapping[str, Any], ops: ArrayOps = NUMPY
) -> Any:
    """Harvey's ABg: ``A / (B + |beta - beta_0|^g)`` [sr-1] (Zemax's ABg scatter model;
    Harvey 1976, doi:10.1117/12.954861; lumos-sat's ``ABG(A, B, g)``)."""
    x = projected_distance(cos_h, cos_d, ops)
    return float(c["a"]) / (float(c["b"]) + ops.power(x, float(c["g"])))


def binomial(
    cos_i: Any, cos_o: Any, cos_h: Any, cos_d: Any, c: Mapping[str, Any], ops: ArrayOps = NUMPY
) -> Any:
    """Greynolds' binomial model [sr-1] (Greynolds 2015, "General physically-realistic BRDF
    models for computing stray light from arbitrary isotropic surfaces", Proc. SPIE 9629,
    doi:10.1117/12.2196071), in lumos-sat's ``BINOMIAL(B, C, d, l1)`` convention::

        log10 f = sum_k V^k [ sum_j b[k][j] D^j + 1/2 sum_j c[k][j] log10(1 + d^(j + l1) D^2) ]

    with ``D = |beta - beta_0|`` and ``V = beta . beta_0`` (module doc).
    """
    dist = projected_distance(cos_h, cos_d, ops)
    v = cos_i * cos_o - cos_light_view(cos_d)
    b = np.asarray(c["b"], dtype=float)
    cc = np.asarray(c["c"], dtype=float)
    d, l1 = float(c["d"]), int(c["l1"])
    log_f = 0.0 * dist
    v_k = 1.0 + 0.0 * v  # V^k
    for k in range(b.shape[0]):
        term = 0.0 * dist
        d_j = 1.0 + 0.0 * dist  # D^j
        for j in range(b.shape[1]):
            term = term + float(b[k, j]) * d_j
            d_j = d_j * dist
        for j in range(cc.shape[1]):
            term = term + 0.5 * float(cc[k, j]) * ops.log10(1.0 + d ** (j + l1) * dist * dist)
        log_f = log_f + term * v_k
        v_k = v_k * v
    return ops.exp10(log_f)


def schlick_fresnel(cos_d: Any, f0: float, ops: ArrayOps = NUMPY) -> Any:
    """Schlick's approximation ``F0 + (1 - F0)(1 - cos_d)^5`` [1] (Schlick 1994,
    doi:10.1111/1467-8659.1330233)."""
    m = 1.0 - ops.clip(cos_d, 0.0, 1.0)
    return f0 + (1.0 - f0) * (m * m) * (m * m) * m


def exact_fresnel(cos_d: Any, f0: float, ops: ArrayOps = NUMPY) -> Any:
    """Unpolarised Fresnel reflectance [1] of a dielectric with the real index
    ``n = (1 + sqrt(F0)) / (1 - sqrt(F0))`` (the one whose normal reflectance is F0), seen
    from outside (Born & Wolf, sec. 1.5.2)."""
    r = float(np.sqrt(f0))
    n = (1.0 + r) / max(1.0 - r, 1e-12)
    cos = ops.clip(cos_d, 0.0, 1.0)
    ct = ops.sqrt(ops.maximum(1.0 - (1.0 - cos * cos) / (n * n), 0.0))
    rs = (cos - n * ct) / ops.maximum(cos + n * ct, 1e-30)
    rp = (n * cos - ct) / ops.maximum(n * cos + ct, 1e-30)
    return ops.minimum(0.5 * (rs * rs + rp * rp), 1.0)


def microfacet_fresnel(cos_d: Any, c: Mapping[str, Any], ops: ArrayOps = NUMPY) -> Any:
    """The microfacet form's Fresnel term F(theta_d) [1] (``fresnel``: schlick or exact)."""
    f0 = float(c["f0"])
    exact = c["fresnel"] == "exact"
    return exact_fresnel(cos_d, f0, ops) if exact else schlick_fresnel(cos_d, f0, ops)


def microfacet(
    cos_i: Any, cos_o: Any, cos_h: Any, cos_d: Any, c: Mapping[str, Any], ops: ArrayOps = NUMPY
) -> Any:
    """A Lambertian term and a Cook-Torrance lobe [sr-1]::

        f = rho_d / pi + (1 - rho_d) F(theta_d) D(theta_h) G1(i) G1(o) / (4 cos_i cos_o)

    D the GGX or Beckmann normal distribution and G1 the separable Smith masking of Walter
    et al. 2007 (doi:10.2312/EGWR/EGSR07/195-206; the same terms as the ``ggx`` and
    ``beckmann`` models), F Schlick's or the exact Fresnel term of normal reflectance F0.
    The lobe is weighted by ``1 - rho_d``, so that the directional albedo is at most
    ``rho_d + (1 - rho_d) = 1`` for every rho_d, F0 in [0, 1].
    """
    lobe = ops.microfacet(cos_i, cos_o, cos_h, float(c["roughness"]), str(c["distribution"]))
    rho_d = float(c["diffuse"])
    return rho_d / np.pi + (1.0 - rho_d) * microfacet_fresnel(cos_d, c, ops) * lobe
