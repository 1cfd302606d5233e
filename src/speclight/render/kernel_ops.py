"""The array functions the per-hit BRDF weights are written against: numpy's or Dr.Jit's.

Every model's per-pixel weight (:mod:`speclight.render.bsdfs`) is one function of the
shading cosines and an ``ops`` object (:class:`ShadingOps`): with :data:`NUMPY_OPS` it runs
on numpy arrays (the numpy caster, the scalar variants, laser returns, images), with
:func:`drjit_ops` on Dr.Jit arrays inside the single mode's kernel
(:mod:`speclight.render.single_kernel`), so that both paths evaluate one written formula.
It extends the analytic forms' :class:`~speclight.target.brdf_fit.analytic_forms.ArrayOps`
(which the fitted models use) with what the other models need.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from speclight.target.brdf_fit.analytic_forms import ArrayOps

LOG10_2 = float(np.log10(2.0))
LOG2_10 = float(np.log2(10.0))


class ShadingOps(ArrayOps):
    """numpy's array functions (:class:`ArrayOps` and ``exp``, ``where``, ``arccos``,
    ``floor``, ``index``)."""

    #: True for Dr.Jit arrays (the kernel), False for numpy's.
    jit = False

    @staticmethod
    def exp(x: Any) -> Any:
        return np.exp(x)

    @staticmethod
    def where(cond: Any, x: Any, y: Any) -> Any:
        return np.where(cond, x, y)

    @staticmethod
    def arccos(x: Any) -> Any:
        return np.arccos(x)

    @staticmethod
    def floor(x: Any) -> Any:
        return np.floor(x)

    @staticmethod
    def index(x: Any) -> Any:
        """Non-negative whole numbers ``x`` (floats) as integer indices."""
        return np.asarray(x).astype(np.int64)

    @staticmethod
    def zeros_like(x: Any) -> Any:
        return np.zeros_like(x)

    @staticmethod
    def array(values: Any) -> Any:
        """A float array of ``values`` (numpy) in this family."""
        return np.asarray(values, dtype=float)

    @staticmethod
    def gather(values: Any, index: Any) -> Any:
        """``values[index]`` of a flat array of this family."""
        return values[index]


NUMPY_OPS = ShadingOps()


def drjit_ops(dr: Any, float_type: Any, index_type: Any) -> ShadingOps:
    """Dr.Jit's array functions on ``float_type`` arrays (the variant's ``Float64`` in the
    kernel) with ``index_type`` indices (its ``UInt32``)."""

    class DrJitOps(ShadingOps):
        jit = True

        @staticmethod
        def sqrt(x: Any) -> Any:
            return dr.sqrt(x)

        @staticmethod
        def clip(x: Any, low: float, high: float) -> Any:
            return dr.clip(x, low, high)

        @staticmethod
        def maximum(x: Any, y: Any) -> Any:
            return dr.maximum(x, y)

        @staticmethod
        def minimum(x: Any, y: Any) -> Any:
            return dr.minimum(x, y)

        @staticmethod
        def power(x: Any, y: Any) -> Any:
            return dr.power(x, y)

        @staticmethod
        def log10(x: Any) -> Any:
            return dr.log2(x) * LOG10_2

        @staticmethod
        def exp10(x: Any) -> Any:
            return dr.exp2(x * LOG2_10)

        @staticmethod
        def exp(x: Any) -> Any:
            return dr.exp(x)

        @staticmethod
        def where(cond: Any, x: Any, y: Any) -> Any:
            return dr.select(cond, x, y)

        @staticmethod
        def arccos(x: Any) -> Any:
            return dr.acos(x)

        @staticmethod
        def floor(x: Any) -> Any:
            return dr.floor(x)

        @staticmethod
        def index(x: Any) -> Any:
            return index_type(x)

        @staticmethod
        def zeros_like(x: Any) -> Any:
            return dr.zeros(type(x), dr.width(x))

        @staticmethod
        def array(values: Any) -> Any:
            return float_type(np.ascontiguousarray(values, dtype=np.float64))

        @staticmethod
        def gather(values: Any, index: Any) -> Any:
            return dr.gather(float_type, values, index)

        @staticmethod
        def microfacet(cos_i: Any, cos_o: Any, cos_h: Any, alpha: float, kind: str) -> Any:
            from speclight.target.microfacet_terms import microfacet_weight  # one copy of the terms

            ops = DrJitOps()
            weight = microfacet_weight(cos_i, cos_o, cos_h, alpha, kind, ops)  # type: ignore[arg-type]
            return weight / dr.maximum(cos_i, 1e-12)

    return DrJitOps()
