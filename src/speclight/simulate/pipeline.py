"""The ``simulate`` pipeline."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from speclight.errors import InputError
from speclight.scenario import LoadedScenario
from speclight.simulate import variables as v
from speclight.simulate.dataset import geometry_dataset, global_attributes
from speclight.simulate.geometry_stage import Geometry, compute_geometry
from speclight.simulate.radiometry import (
    atmosphere_transmission,
    instrument_response,
    wavelength_grid_nm,
)
from speclight.simulate.ranging_stage import laser_ranging, prepare_ranging
from speclight.simulate.reflection import build_target, render_reflection
from speclight.simulate.spectral_dataset import add_images, add_spectral


@dataclass
class SimulationResult:
    """The output dataset and the notes a user should read about the run."""

    dataset: xr.Dataset
    geometry: Geometry
    notes: list[str] = field(default_factory=list)


def _visibility_notes(geo: Geometry) -> list[str]:
    n = geo.flags.size
    observable = geo.observable
    lit = observable & (geo.sunlit_fraction > 0)
    notes = [
        f"{n} epochs: {int(observable.sum())} above the minimum elevation, "
        f"{int(lit.sum())} of them sunlit"
    ]
    if not np.any(~geo.orbit_ok) and not np.any(lit):
        notes.append(
            "the target is never both sunlit and above the minimum elevation in this time "
            "window: its brightness is zero or not observable at every epoch"
        )
    failed = int(np.count_nonzero(geo.flags & v.FLAG_ORBIT_FAILED))
    if failed:
        notes.append(f"{failed} epochs have no target position (flag orbit_failed)")
    return notes


def simulate(loaded: LoadedScenario, progress: bool = False) -> SimulationResult:
    """Run one scenario through the pipeline.

    Parameters
    ----------
    loaded
        A validated scenario (see :func:`speclight.scenario.load_scenario`).
    progress
        Show progress bars (for terminals).

    Returns
    -------
    SimulationResult
        The dataset of SPEC section 4 and notes for the user.
    """
    try:
        return _simulate(loaded, progress)
    except InputError as exc:
        if exc.source is None:  # say which scenario the bad field is in
            raise InputError(exc.message, source=loaded.source, field=exc.field) from exc
        raise


def _simulate(loaded: LoadedScenario, progress: bool) -> SimulationResult:
    sc = loaded.scenario
    target = build_target(loaded) if sc.target is not None else None  # once, and early
    geo = compute_geometry(loaded)
    wavelength_nm = wavelength_grid_nm(sc.spectrum)
    # None without lasers; sets flag bits
    setup = prepare_ranging(loaded, geo, wavelength_nm, target=target)
    reflection = render_reflection(
        loaded,
        geo,
        wavelength_nm,
        progress=progress,
        on_hits=setup.on_hits_for if setup is not None else None,
        target=target,
    )
    elevation = np.where(geo.observable, geo.elevation_deg, np.nan)
    transmission = atmosphere_transmission(loaded, wavelength_nm, elevation)
    radiometry = None
    if reflection.intensity_W_sr_nm is not None:
        radiometry = instrument_response(
            loaded, wavelength_nm, reflection.intensity_W_sr_nm, transmission, geo.range_m
        )
    ranging = None
    if setup is not None:
        ranging = laser_ranging(loaded, geo, wavelength_nm, setup, transmission, radiometry)
    ds = geometry_dataset(geo)  # after rendering and ranging: they set flag bits
    ds = add_spectral(ds, wavelength_nm, reflection, transmission, radiometry)
    ds = add_images(ds, reflection.images, reflection.part_names)
    extra: dict[str, str] = {"render_mode": sc.render.mode, "atmosphere_model": sc.atmosphere.model}
    if reflection.variant:
        extra["render_variant"] = reflection.variant
    ds.attrs.update(global_attributes(loaded, extra))
    notes = _visibility_notes(geo)
    if ranging is not None:
        ds = ranging.add_to(ds)
        notes += ranging.notes
    return SimulationResult(dataset=ds, geometry=geo, notes=notes)
