"""``measured``: a lab BRDF table, or an RGL ``.bsdf`` file through Mitsuba's plugin.

A lab table (:mod:`speclight.target.brdf_table`) is a function f(theta_h, theta_d) measured at
one wavelength, inside its support; outside it, an analytic model fitted to it (its
*extension*). The main channel carries the table's part, a block of one channel the
extension's (:meth:`MeasuredTableBsdf.outside_support`: the renders report that light as the
fraction from outside the support). The material's ``reflectance`` scales both by
``R(lambda) / R(table wavelength)``. Single mode only: path mode has no model of it yet.

An RGL file (:mod:`speclight.render.rgl`, Dupuy & Jakob 2018, doi:10.1145/3272127.3275059)
does not factorise into a geometric weight times one spectrum: its light goes through a block
of channels, one per wavelength node of the file, weighted by Mitsuba's ``measured`` plugin
per pixel; path mode puts the plugin in the scene. Measured BRDFs hold intensity only: they
have no polarisation model.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.render import rgl
from speclight.render.bsdfs.bsdf_interface import F64, I64, MaterialBsdf, normalised_reflectance
from speclight.target.brdf_table import DEFAULT_EXTENSION, MeasuredBRDF, load_brdf_table
from speclight.target.rgl_file import load_rgl_info


class MeasuredTableBsdf(MaterialBsdf):
    """The table's ``f cos_i`` inside its support (main channel) and the extension's outside
    it (a block of one channel), both times the reflectance ratio."""

    @property
    def table(self) -> MeasuredBRDF:
        m = self.material
        return load_brdf_table(str(m.brdf_table), m.extension or DEFAULT_EXTENSION)

    def main_weight(self, cos_i: F64, cos_o: F64, cos_h: F64, cos_d: F64, mirror_ok: F64) -> F64:
        return self.table.table_part(cos_h, cos_d) * cos_i

    def _ratio(self, wavelength_nm: F64) -> F64:
        m = self.material
        where = f"target.materials.{m.name}"
        return normalised_reflectance(m.reflectance, self.table.wavelength_nm, wavelength_nm, where)

    def main_factor(self, cos_half_phase: F64, wavelength_nm: F64) -> F64:
        ratio = self._ratio(wavelength_nm)
        return np.broadcast_to(ratio[None, :], (len(cos_half_phase), len(wavelength_nm)))

    def block_size(self) -> int:
        return 1

    @classmethod
    def planned_block_size(
        cls, given: Mapping[str, Any], resolve: Callable[[str], Path] | None
    ) -> int:
        return 1

    def block_weights(self, cos_i: F64, cos_o: F64, cos_h: F64, cos_d: F64) -> tuple[I64, I64, F64]:
        rows = np.arange(len(cos_i))
        outside = self.table.extension_part(cos_i, cos_o, cos_h, cos_d)
        return rows, np.zeros(len(cos_i), np.int64), outside * cos_i

    def outside_support(self) -> NDArray[np.bool_]:
        return np.ones(1, dtype=bool)

    def block_factor(self, wavelength_nm: F64) -> F64:
        return self._ratio(wavelength_nm)[None, :]


class MeasuredRglBsdf(MaterialBsdf):
    """No main channel; a block of one channel per wavelength node of the file."""

    def main_weight(self, cos_i: F64, cos_o: F64, cos_h: F64, cos_d: F64, mirror_ok: F64) -> F64:
        return np.zeros_like(cos_i)

    def main_factor(self, cos_half_phase: F64, wavelength_nm: F64) -> F64:
        return np.zeros((len(cos_half_phase), len(wavelength_nm)))

    def block_size(self) -> int:
        return rgl.node_count(self.material)

    @classmethod
    def planned_block_size(
        cls, given: Mapping[str, Any], resolve: Callable[[str], Path] | None
    ) -> int:
        if resolve is None:
            return 0
        try:
            return len(load_rgl_info(str(resolve(str(given["brdf_table"])))).wavelength_nm)
        except (InputError, OSError, ValueError, KeyError):
            return 0

    def entries_per_pixel(self) -> int:
        return rgl.node_count(self.material)

    def block_weights(self, cos_i: F64, cos_o: F64, cos_h: F64, cos_d: F64) -> tuple[I64, I64, F64]:
        w = rgl.pixel_weights(self.material, cos_i, cos_o, cos_d)  # (P, W)
        rows = np.repeat(np.arange(len(cos_i)), w.shape[1])
        return rows, np.tile(np.arange(w.shape[1]), len(cos_i)), w.ravel()

    def block_factor(self, wavelength_nm: F64) -> F64:
        return rgl.hat_factor(self.material, wavelength_nm)

    def path_bsdf(self, lo_nm: float, hi_nm: float, coat: str = "spectral") -> dict[str, Any]:
        return rgl.path_bsdf(self.material)
