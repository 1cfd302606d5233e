"""The reflection stage's intensity and its derivatives in the roughness, for a fit.

:class:`ReflectionGradient` gives, for a fixed geometry and a set of observable epochs, the
target's intensity as :func:`speclight.simulation.reflection.render_reflection` computes it
(single-scattering render) and its derivatives in the roughness of chosen materials
(:func:`speclight.render.single_gradient.render_single_gradient`). Both are linear in the
renders they sum, so the derivative is the same sum of the renders' derivatives:

* the Sun: the sunlit epochs rendered with the full Sun and scaled by the penumbra's sunlit
  fraction; a target with articulated parts rendered per pose, with the joint angles of
  :func:`~speclight.target.articulation.joint_angles_rad` grouped by
  :func:`~speclight.render.articulated.posed_groups`, as the pipeline does;
* Earthshine: one render per lit cell of the visible Earth cap and epoch
  (:func:`~speclight.simulation.earthshine_stage.earthshine_cells`), the target as built
  (articulated parts at their reference pose, as in the pipeline), summed per epoch by
  :func:`~speclight.simulation.earthshine_stage.sum_over_cells`.

Only ``render.mode: single`` and ``beckmann`` / ``ggx`` materials have a derivative here
(:func:`speclight.render.single_gradient.gradient_problem`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from speclight.constants import AU_M
from speclight.illumination import solar_irradiance_W_m2_nm
from speclight.render.articulated import posed_groups
from speclight.render.session import RenderSession
from speclight.render.single_gradient import render_single_gradient
from speclight.scenario import LoadedScenario
from speclight.simulation.earthshine_stage import EarthshineCells, earthshine_cells, sum_over_cells
from speclight.simulation.geometry_stage import Geometry
from speclight.simulation.reflection import build_joints, build_target
from speclight.target.articulation import joint_angles_rad
from speclight.target.parts import Target

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


def _unit(x: F64) -> F64:
    """Rows divided by their norms, as :func:`speclight.render.render_intensity` does."""
    return x / np.linalg.norm(x, axis=1, keepdims=True)


def with_roughness(target: Target, values: dict[str, float]) -> Target:
    """``target`` with the roughness of the named materials set to ``values``."""
    mats = {
        m.name: replace(m, roughness=values[m.name]) if m.name in values else m
        for m in target.materials
    }
    parts = tuple(replace(p, material=mats[p.material.name]) for p in target.parts)
    return Target(parts=parts)


class ReflectionGradient:
    """``self(alpha)`` -> intensity (M, L) and d intensity / d alpha (K, M, L) [W sr-1 nm-1].

    Parameters
    ----------
    loaded
        The scenario (``render.mode: single``).
    geometry
        The geometry of a simulation of ``loaded``.
    wavelength_nm
        (L,) the simulation's wavelength grid [nm].
    rough
        Names of the K materials to differentiate (keys of ``target.materials``).
    epochs
        (M,) observable epochs (indices into ``geometry``) to compute.
    """

    def __init__(
        self,
        loaded: LoadedScenario,
        geometry: Geometry,
        wavelength_nm: F64,
        rough: list[str],
        epochs: I64,
    ) -> None:
        sc = loaded.scenario
        geo = geometry
        assert sc.target is not None
        self.rough = list(rough)
        self.wavelength_nm = wavelength_nm
        self.resolution_px = int(sc.render.resolution_px)
        self.target = build_target(loaded)
        self.session = RenderSession.create("single", sc.render.variant, self.target.materials)
        self.caster = self.session.caster(self.target)
        self.n = len(epochs)
        solar = solar_irradiance_W_m2_nm(wavelength_nm, geo.sun_distance_m / AU_M)
        sunlit = geo.sunlit_fraction if sc.illumination.sun else np.zeros(geo.t_s.size)
        #: positions in ``epochs`` of the sunlit ones, and those epochs
        self.lit = np.flatnonzero(sunlit[epochs] > 0)
        lit = np.asarray(epochs)[self.lit]
        self.sun_dir = _unit(geo.sun_direction_body[lit])
        self.obs_dir = _unit(geo.observer_direction_body[lit])
        self.irradiance = solar[lit]
        self.sunlit = sunlit[lit, None]
        self.joints = build_joints(loaded, self.target) if sc.target.articulation else ()
        self.step_deg = float(sc.target.articulation_step_deg)
        self.angles = np.zeros((lit.size, 0))
        if self.joints:
            # the angles of every sunlit observable epoch, as the pipeline computes them
            every = np.flatnonzero(geo.observable & (sunlit > 0))
            angles = joint_angles_rad(
                self.joints, geo.sun_direction_body[every], geo.time_utc[every]
            )
            self.angles = angles[np.searchsorted(every, lit)]
        self.cells: EarthshineCells | None = None
        if sc.illumination.earthshine is not None:
            self.cells = earthshine_cells(loaded, geo, solar, np.asarray(epochs))

    def _sun(self, target: Target) -> tuple[F64, F64]:
        """Sun-lit intensity (S, L) and derivatives (K, S, L) of the sunlit epochs."""
        k, n_wl = len(self.rough), self.wavelength_nm.size
        if not self.joints:
            return render_single_gradient(
                target, self.sun_dir, self.obs_dir, self.irradiance, self.wavelength_nm,
                self.caster, self.resolution_px, self.rough,
            )  # fmt: skip
        intensity = np.full((self.lit.size, n_wl), np.nan)
        grad = np.full((k, self.lit.size, n_wl), np.nan)
        for idx, posed in posed_groups(target, self.joints, self.angles, self.step_deg):
            intensity[idx], grad[:, idx] = render_single_gradient(
                posed, self.sun_dir[idx], self.obs_dir[idx], self.irradiance[idx],
                self.wavelength_nm, self.session.caster(posed), self.resolution_px, self.rough,
            )  # fmt: skip
            self.session.forget(posed)  # one scene alive at a time, as in the pipeline
        return intensity, grad

    def __call__(self, alpha: F64) -> tuple[F64, F64]:
        """Intensity (M, L) and its derivatives (K, M, L) at roughness ``alpha`` (K,)."""
        k, n_wl = len(self.rough), self.wavelength_nm.size
        values = dict(zip(self.rough, (float(a) for a in np.asarray(alpha)), strict=True))
        target = with_roughness(self.target, values)
        intensity = np.zeros((self.n, n_wl))
        grad = np.zeros((k, self.n, n_wl))
        if self.lit.size:
            sun, d_sun = self._sun(target)
            intensity[self.lit] = sun * self.sunlit
            grad[:, self.lit] = d_sun * self.sunlit
        if self.cells is not None and self.cells.epoch.size:
            c = self.cells
            es, d_es = render_single_gradient(
                target, _unit(c.source_body), _unit(c.observer_body), c.irradiance_W_m2_nm,
                self.wavelength_nm, self.caster, self.resolution_px, self.rough,
            )  # fmt: skip
            intensity = intensity + sum_over_cells(self.n, c.epoch, es)
            grad = grad + np.stack([sum_over_cells(self.n, c.epoch, d) for d in d_es])
        return intensity, grad


__all__ = ["ReflectionGradient", "with_roughness"]
