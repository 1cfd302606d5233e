"""Earthshine in the pipeline: the lit Earth cap's cells rendered like the Sun, summed.

:func:`earthshine_cells` lists the renders (one per lit cell of the visible Earth cap and
epoch: :mod:`speclight.illumination.earthshine`), :func:`sum_over_cells` adds them up per
epoch; :func:`earthshine_intensity` (the reflection stage) and the roughness-gradient pass
(:mod:`speclight.simulation.reflection_gradient`) both go through them, so that they light the
target alike.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from speclight.render.session import RenderSession
from speclight.scenario import LoadedScenario
from speclight.simulation.geometry_stage import Geometry, pole_body
from speclight.target.parts import Target

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


@dataclass(frozen=True)
class EarthshineCells:
    """The R renders of the Earthshine of some epochs: one per lit cell and epoch."""

    #: (R,) the epoch of each render, an index into the ``epochs`` it was made for.
    epoch: I64
    #: (R,) the cell of each render, an index into the cap's cells.
    cell: I64
    #: (R, 3) unit vectors from the target toward the cell (body frame).
    source_body: F64
    #: (R, 3) unit vectors from the target toward the observer (body frame).
    observer_body: F64
    #: (R, L) the cell's irradiance at the target, ``w_k E_sun`` [W m-2 nm-1].
    irradiance_W_m2_nm: F64


def earthshine_cells(
    loaded: LoadedScenario, geo: Geometry, solar: F64, epochs: I64
) -> EarthshineCells:
    """The Earthshine renders of ``epochs`` (observable ones: indices into ``geo``).

    ``solar`` (N, L): the solar irradiance at the target at every epoch of ``geo``.
    """
    from speclight.attitude.quaternion import quat_conjugate, quat_rotate
    from speclight.illumination.earthshine import earthshine_sources

    es = loaded.scenario.illumination.earthshine
    assert es is not None
    q = geo.quaternion_body_to_gcrs[epochs]
    sun_gcrs = quat_rotate(q, geo.sun_direction_body[epochs])
    dirs, weights = earthshine_sources(geo.r_target_gcrs_m[epochs], sun_gcrs, es.albedo, es.samples)
    weights = np.nan_to_num(weights)
    epoch, cell = np.nonzero(weights > 0)
    sources_body = quat_rotate(quat_conjugate(q[epoch]), dirs[epoch, cell])
    return EarthshineCells(
        epoch=epoch.astype(np.int64),
        cell=cell.astype(np.int64),
        source_body=np.asarray(sources_body, dtype=float).reshape(-1, 3),
        observer_body=geo.observer_direction_body[epochs][epoch],
        irradiance_W_m2_nm=solar[epochs][epoch] * weights[epoch, cell][:, None],
    )


def sum_over_cells(n_epochs: int, epoch: I64, values: NDArray[np.float64]) -> F64:
    """Per-epoch sums (n_epochs, ...) of the renders' ``values`` (R, ...) (NaN as 0)."""
    total = np.zeros((n_epochs, *values.shape[1:]))
    np.add.at(total, epoch, np.nan_to_num(values))
    return total


def earthshine_intensity(
    loaded: LoadedScenario,
    geo: Geometry,
    solar: F64,
    wavelength_nm: F64,
    target: Target,
    session: RenderSession,
) -> tuple[F64, F64 | None]:
    """(N, L) intensity from Earthshine (:mod:`speclight.illumination.earthshine`): one
    render per lit cell of the visible Earth cap and observable epoch, the cell as the Sun
    in its direction with the irradiance ``w_k E_sun``. Unobservable epochs get NaN. The
    target is rendered as built (articulated parts at their reference pose).

    With ``render.polarization`` also its Stokes Q, U, V (N, L, 3) (else None): the light of
    each cell is taken as unpolarised (the Rayleigh polarisation of the sky over the Earth
    is not modelled)."""
    from speclight.render import render_intensity

    sc = loaded.scenario
    n = geo.t_s.size
    out = np.full((n, wavelength_nm.size), np.nan)
    idx = np.flatnonzero(geo.observable)
    cells = earthshine_cells(loaded, geo, solar, idx)
    out[idx] = 0.0
    polarized = sc.render.polarization
    stokes = np.full((n, wavelength_nm.size, 3), np.nan) if polarized else None
    if stokes is not None:
        stokes[idx] = 0.0
    if cells.epoch.size == 0:
        return out, stokes
    result = render_intensity(
        target,
        cells.source_body,
        cells.observer_body,
        cells.irradiance_W_m2_nm,
        wavelength_nm,
        mode=session.mode,
        variant=sc.render.variant,
        session=session,
        resolution_px=sc.render.resolution_px,
        samples_per_pixel=sc.render.samples_per_pixel,
        seed=sc.render.seed,
        workers=os.cpu_count(),
        polarization=polarized,
        pole_body=pole_body(geo)[idx][cells.epoch] if polarized else None,
    )
    out[idx] = sum_over_cells(idx.size, cells.epoch, result.intensity_W_sr_nm)
    if stokes is not None and result.stokes_W_sr_nm is not None:
        stokes[idx] = sum_over_cells(idx.size, cells.epoch, result.stokes_W_sr_nm)
    return out, stokes
