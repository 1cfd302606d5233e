"""Every lit, visible surface element of the observed epochs, rendered once for a BRDF fit.

In the single-scattering render (:mod:`speclight.render.single`) a surface's contribution to
the intensity is ``E sum_pixels A_pix f(cos_i, cos_o, cos_h, cos_d) cos_i``: given the
geometry (which pixels see which material, lit, unshadowed, and their cosines) it is linear
in the BRDF value ``f``. So the target is rendered once per site and light (the Sun, and
each lit Earthshine cell as :mod:`speclight.simulation.earthshine_stage` lights it), every
hit of a fitted material is kept with its cosines (the render's ``on_shading`` hook), and
the fit evaluates the analytic BRDFs on these hits in numpy, with no render per iteration.
Hits of one epoch, light and material with the same cosines (a flat face: every pixel) are
merged into one record with their summed area, so a faceted target keeps a few records per
epoch and light.

Each record's ``weight_m2`` is its area times the light's irradiance relative to the Sun's
on the target (1 for the Sun; the cell's ``w_k`` for Earthshine), divided by the sunlit
fraction: the unit of the band reflectance factor (docs/fit.md), which the pipeline divides
by the same irradiance.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]
#: Cosines that agree to this are one record [1] (float32 normals of one flat face agree
#: exactly; 1e-7 is 0.02 arcsec).
COSINE_QUANTUM = 1e-7
#: Most records held for a fit (about 50 bytes each: 1 GB); a curved mesh merges few hits.
MAX_RECORDS = 20_000_000


@dataclass
class SurfaceRecords:
    """Lit, visible elements of the fitted surfaces (one row per record).

    Attributes
    ----------
    epoch
        (K,) the epoch of each record (an index the caller chose, e.g. the time index).
    surface
        (K,) the fitted surface (index into the fit's list of surfaces).
    cos_i, cos_o, cos_h, cos_d
        (K,) the cosines of :mod:`speclight.render.shading` [1].
    weight_m2
        (K,) area [m2] times the light's irradiance over the Sun's times sunlit fraction.
    """

    epoch: I64
    surface: I64
    cos_i: F64
    cos_o: F64
    cos_h: F64
    cos_d: F64
    weight_m2: F64

    @classmethod
    def join(cls, parts: list[SurfaceRecords]) -> SurfaceRecords:
        """The records of ``parts`` one after the other."""
        names = ("epoch", "surface", "cos_i", "cos_o", "cos_h", "cos_d", "weight_m2")
        if not parts:
            return cls(np.zeros(0, np.int64), np.zeros(0, np.int64), *[np.zeros(0)] * 5)
        return cls(*[np.concatenate([getattr(p, n) for p in parts]) for n in names])

    def shifted(self, offset: int) -> SurfaceRecords:
        """The same records with ``offset`` added to every epoch index."""
        return replace(self, epoch=self.epoch + offset)


class _Collector:
    """The ``on_shading`` hook: merges the hits of the fitted materials into records."""

    def __init__(self, surface_of_material: I64, epoch_of: I64, factor: F64) -> None:
        self.surface_of_material = surface_of_material
        self.epoch_of = epoch_of
        self.factor = factor
        self.parts: list[SurfaceRecords] = []
        self.count = 0

    def __call__(self, epochs: I64, mat: I64, cos_i: F64, cos_o: F64, cos_h: F64,
                 cos_d: F64, pixel_area_m2: float) -> None:  # fmt: skip
        surface = self.surface_of_material[mat]
        keep = np.flatnonzero(surface >= 0)
        if keep.size == 0:
            return
        cos = [np.asarray(c, dtype=float)[keep] for c in (cos_i, cos_o, cos_h, cos_d)]
        key = np.stack(
            [epochs[keep], surface[keep], *[np.rint(c / COSINE_QUANTUM) for c in cos[:3]]],
            axis=1,
        ).astype(np.int64)
        unique, inverse = np.unique(key, axis=0, return_inverse=True)
        inverse = inverse.ravel()
        n = np.bincount(inverse).astype(float)
        mean = [np.bincount(inverse, c) / n for c in cos]
        light = unique[:, 0]
        self.parts.append(
            SurfaceRecords(
                self.epoch_of[light], unique[:, 1], mean[0], mean[1], mean[2], mean[3],
                n * pixel_area_m2 * self.factor[light],
            )
        )  # fmt: skip
        self.count += unique.shape[0]
        if self.count > MAX_RECORDS:
            raise InputError(
                f"the fitted surfaces give more than {MAX_RECORDS} distinct surface elements "
                "(a curved mesh: every pixel is its own element); lower "
                "render.resolution_px or fit fewer epochs",
                field="render.resolution_px",
            )


def _unit(x: F64) -> F64:
    return np.asarray(x / np.linalg.norm(x, axis=1, keepdims=True))


def shading_records(loaded: Any, geometry: Any, surfaces: list[str], epochs: I64) -> SurfaceRecords:
    """The records of the fitted materials at ``epochs`` of one simulation.

    Parameters
    ----------
    loaded
        The scenario as simulated (``render.mode: single``, no articulated parts).
    geometry
        Its :class:`~speclight.simulation.geometry_stage.Geometry`.
    surfaces
        Names of the fitted materials (keys of ``target.materials``); a record's
        ``surface`` is the position of its material in this list.
    epochs
        (E,) the observable epochs to render (indices into ``geometry``); a record's
        ``epoch`` is such an index.
    """
    from speclight.constants import AU_M
    from speclight.illumination import solar_irradiance_W_m2_nm
    from speclight.render import material_channels as channels
    from speclight.render.session import RenderSession
    from speclight.render.single import geometric_weights
    from speclight.simulation.earthshine_stage import earthshine_cells
    from speclight.simulation.radiometry import wavelength_grid_nm
    from speclight.simulation.reflection import build_target

    sc = loaded.scenario
    geo = geometry
    target = build_target(loaded)
    names = [m.name for m in target.materials]
    surface_of_material = np.array(
        [surfaces.index(n) if n in surfaces else -1 for n in names], dtype=np.int64
    )
    session = RenderSession.create("single", sc.render.variant, target.materials)
    caster = session.caster(target)
    epochs = np.asarray(epochs, dtype=np.int64)
    sunlit = geo.sunlit_fraction if sc.illumination.sun else np.zeros(geo.t_s.size)
    per_sunlit = np.divide(1.0, sunlit, out=np.zeros_like(sunlit), where=sunlit > 0)
    parts: list[SurfaceRecords] = []

    def cast(light_dir: F64, obs_dir: F64, epoch_of: I64, factor: F64) -> None:
        if epoch_of.size == 0:
            return
        collect = _Collector(surface_of_material, epoch_of, factor)
        geometric_weights(
            target, _unit(light_dir), _unit(obs_dir), caster, int(sc.render.resolution_px),
            rays_per_batch=channels.rays_per_batch(target.materials), on_shading=collect,
        )  # fmt: skip
        parts.extend(collect.parts)

    lit = epochs[sunlit[epochs] > 0]
    cast(geo.sun_direction_body[lit], geo.observer_direction_body[lit], lit, np.ones(lit.size))
    if sc.illumination.earthshine is not None:
        wavelength_nm = wavelength_grid_nm(sc.spectrum)
        solar = solar_irradiance_W_m2_nm(wavelength_nm, geo.sun_distance_m / AU_M)
        cells = earthshine_cells(loaded, geo, solar, epochs)
        epoch_of = epochs[cells.epoch]
        # w_k of each cell (its irradiance over the Sun's: grey), per sunlit fraction
        ratio = cells.irradiance_W_m2_nm.sum(axis=1) / solar[epoch_of].sum(axis=1)
        cast(cells.source_body, cells.observer_body, epoch_of, ratio * per_sunlit[epoch_of])
    return SurfaceRecords.join(parts)


def yawed(geometry: Any, yaw_deg: float) -> Any:
    """``geometry`` with the body turned by ``yaw_deg`` [deg] about its +z axis (the nadir
    axis of ``attitude: nadir``): the body-to-GCRS quaternion times that rotation, and every
    body-frame direction turned back by it."""
    from speclight.attitude.quaternion import (
        quat_conjugate,
        quat_from_axis_angle,
        quat_multiply,
        quat_rotate,
    )

    geo = geometry
    turn = quat_from_axis_angle(np.array([0.0, 0.0, 1.0]), np.deg2rad(yaw_deg))
    back = quat_conjugate(turn)
    return replace(
        geo,
        quaternion_body_to_gcrs=quat_multiply(geo.quaternion_body_to_gcrs, turn),
        sun_direction_body=quat_rotate(back, geo.sun_direction_body),
        observer_direction_body=quat_rotate(back, geo.observer_direction_body),
        phase_vector_body=quat_rotate(back, geo.phase_vector_body),
    )
