"""The ``simulate`` pipeline."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from speclight import schema as v
from speclight.errors import InputError
from speclight.io.deferred_dask import defer_dask_array_import
from speclight.progress import stage
from speclight.render.session import RenderSession
from speclight.scenario import LoadedScenario
from speclight.scenario.sections_geometry import Observer
from speclight.simulation.dataset import describe_run, geometry_dataset
from speclight.simulation.geometry_stage import Geometry, scenario_geometry
from speclight.simulation.map_reflection import map_reflection
from speclight.simulation.memory import check_run_limits, grid_epochs
from speclight.simulation.per_material import (
    add_per_material,
    laser_material_factors,
    material_labels,
    solar_material_factors,
)
from speclight.simulation.polarimetry import add_polarization
from speclight.simulation.radiometry import (
    atmosphere_transmission,
    instrument_response,
    wavelength_grid_nm,
)
from speclight.simulation.ranging_stage import laser_ranging, prepare_ranging
from speclight.simulation.reflection import build_target, render_reflection
from speclight.simulation.spectral_dataset import add_images, add_spectral


@dataclass
class SimulationResult:
    """The output dataset, the geometry it was computed on (reusable: see :func:`simulate`)
    and the notes a user should read about the run."""

    dataset: xr.Dataset
    geometry: Geometry
    notes: list[str] = field(default_factory=list)


def _visibility_notes(geo: Geometry, observer: Observer) -> list[str]:
    n = geo.flags.size
    high = (geo.flags & (v.FLAG_ORBIT_FAILED | v.FLAG_BELOW_MIN_ELEVATION)) == 0
    dark = high & ((geo.flags & v.FLAG_DAYLIGHT) == 0)
    lit = geo.observable & (geo.sunlit_fraction > 0)
    notes = [
        f"{n} epochs: {int(high.sum())} above the minimum elevation "
        f"({observer.min_elevation_deg:g} deg), {int(dark.sum())} of them in a dark sky (the "
        f"Sun below {observer.max_sun_elevation_deg:g} deg), {int(lit.sum())} of those with "
        "the target sunlit (observable)"
    ]
    if not np.any(~geo.orbit_ok) and not np.any(lit):
        notes.append(
            "the target is never observable in this time window (above the minimum "
            "elevation, in a dark sky and sunlit at once): its brightness is zero or not "
            "observable at every epoch"
        )
    if np.any(high) and not np.any(dark):
        notes.append(
            "every epoch above the minimum elevation is in daylight (flag daylight: the Sun "
            f"above observer.max_sun_elevation_deg = {observer.max_sun_elevation_deg:g} deg at "
            "the site); `speclight passes SCENARIO` lists the dark-sky passes, and "
            "max_sun_elevation_deg: 90 renders daylight epochs too"
        )
    failed = int(np.count_nonzero(geo.flags & v.FLAG_ORBIT_FAILED))
    if failed:
        notes.append(f"{failed} epochs have no target position (flag orbit_failed)")
    no_attitude = int(np.count_nonzero(geo.flags & v.FLAG_ATTITUDE_UNDEFINED))
    if no_attitude:
        notes.append(
            f"{no_attitude} epochs have no attitude (flag attitude_undefined: outside the "
            "attitude table, or the pointing and constraint directions are parallel)"
        )
    return notes


def simulate(
    loaded: LoadedScenario,
    progress: bool = False,
    *,
    time_utc: NDArray[np.datetime64] | None = None,
    geometry: Geometry | None = None,
) -> SimulationResult:
    """Run one scenario through the pipeline.

    Parameters
    ----------
    loaded
        A validated scenario (see :func:`speclight.scenario.load_scenario`).
    progress
        Show progress bars (for terminals).
    time_utc
        Simulate at these UTC epochs (``datetime64``, e.g. the times of a measured light
        curve) instead of the scenario's time grid.
    geometry
        Reuse the geometry of an earlier run (``result.geometry``) and run only reflection ->
        atmosphere -> instrument (and ranging): for the same orbit, attitude and observer with
        changed materials, bands or render settings, e.g. in a fit. The caller keeps those
        sections of the scenario unchanged; ``time_utc`` must then be ``None``.

    Returns
    -------
    SimulationResult
        The output dataset (see ``docs/scenario.md``) and notes for the user.
    """
    if geometry is not None and time_utc is not None:
        raise InputError("give time_utc or geometry, not both", field="time_utc")
    defer_dask_array_import()  # a run without dask arrays never imports dask.array
    try:
        return _simulate(loaded, progress, time_utc, geometry)
    except InputError as exc:
        if exc.source is None:  # say which scenario the bad field is in
            raise InputError(exc.message, source=loaded.source, field=exc.field) from exc
        raise


def _simulate(
    loaded: LoadedScenario,
    progress: bool,
    time_utc: NDArray[np.datetime64] | None,
    geometry: Geometry | None,
) -> SimulationResult:
    sc = loaded.scenario
    given = geometry.t_s if geometry is not None else time_utc
    check_run_limits(loaded, grid_epochs(sc) if given is None else int(np.size(given)))
    map_mode = sc.render.mode == "map"  # interpolate a reflectivity map: no target, no render
    target = build_target(loaded) if sc.target is not None and not map_mode else None
    # the one render variant of the run, handed to every render (Sun and lasers)
    session = (
        RenderSession.create(
            sc.render.mode, sc.render.variant, target.materials, sc.render.polarization
        )
        if target is not None
        else None
    )
    if geometry is not None:
        geo = geometry
    else:
        with stage("orbit, attitude and geometry", enabled=progress):
            geo = scenario_geometry(loaded, time_utc)
    wavelength_nm = wavelength_grid_nm(sc.spectrum)
    with stage("laser ranging set-up", enabled=progress and bool(sc.illumination.lasers)):
        setup = prepare_ranging(loaded, geo, wavelength_nm, target, session)  # None: no lasers
    flags = geo.flags.copy()  # every stage's flag bits: geometry, render, lasers
    if target is None and not map_mode:  # geometry only: no (N, L) spectra at all
        ds = geometry_dataset(geo, flags)
        modes = {"render_mode": sc.render.mode, "atmosphere_model": sc.atmosphere.model}
        ds = describe_run(ds, loaded, modes)
        return SimulationResult(dataset=ds, geometry=geo, notes=_visibility_notes(geo, sc.observer))
    if map_mode:
        with stage("reflectivity map", enabled=progress):
            reflection = map_reflection(loaded, geo, wavelength_nm)
    else:
        reflection = render_reflection(
            loaded,
            geo,
            wavelength_nm,
            progress=progress,
            on_hits=setup.on_hits_for if setup is not None and _share_rays(session) else None,
            target=target,
            session=session,
        )
    elevation = np.where(geo.observable, geo.elevation_deg, np.nan)
    with stage(f"atmosphere ({sc.atmosphere.model})", enabled=progress):
        transmission = atmosphere_transmission(loaded, wavelength_nm, elevation)
    radiometry = None
    if reflection.intensity_W_sr_nm is not None:
        sunlit = geo.sunlit_fraction if sc.illumination.sun else np.zeros(geo.t_s.size)
        illumination = reflection.solar_irradiance_W_m2_nm * sunlit[:, None] * transmission
        radiometry = instrument_response(
            loaded,
            wavelength_nm,
            reflection.intensity_W_sr_nm,
            transmission,
            geo.range_m,
            illumination_W_m2_nm=illumination,
        )
    ranging = None
    if setup is not None:
        with stage("laser ranging", enabled=progress):
            ranging = laser_ranging(loaded, geo, setup, transmission, radiometry)
    if reflection.flags is not None:
        flags |= reflection.flags
    if setup is not None:
        flags |= setup.flags
    ds = geometry_dataset(geo, flags)
    ds = add_spectral(ds, wavelength_nm, reflection, transmission, radiometry)
    ds = add_images(ds, reflection.images, reflection.part_names)
    if reflection.stokes_W_sr_nm is not None:
        ds = add_polarization(
            ds,
            loaded,
            wavelength_nm,
            reflection.stokes_W_sr_nm,
            transmission,
            geo.range_m,
            radiometry,
            reflection.stokes_std_W_sr_nm,
        )
    if sc.render.per_material and radiometry is not None and radiometry.band_names:
        assert session is not None and target is not None  # per_material: rendered
        solar = None
        if sc.illumination.sun:
            solar = solar_material_factors(
                loaded,
                geo,
                wavelength_nm,
                target,
                session,
                reflection.solar_irradiance_W_m2_nm,
                transmission,
                radiometry,
            )
        laser = None
        if setup is not None:
            laser = laser_material_factors(
                loaded, geo, wavelength_nm, target, session, setup, transmission, radiometry
            )
        names = [m.name for m in target.materials]
        ds = add_per_material(ds, names, material_labels(loaded, target), solar, laser)
    extra: dict[str, str] = {"render_mode": sc.render.mode, "atmosphere_model": sc.atmosphere.model}
    if reflection.variant:
        extra["render_variant"] = reflection.variant
    ds = describe_run(ds, loaded, extra)
    notes = _visibility_notes(geo, sc.observer)
    if ranging is not None:
        ds = ranging.add_to(ds)
        notes += ranging.notes
    return SimulationResult(dataset=ds, geometry=geo, notes=notes)


def _share_rays(session: RenderSession | None) -> bool:
    """Whether the lasers reuse the Sun render's primary rays (``on_hits``).

    Sharing saves the lasers' own ray casts but makes the Sun render read every primary hit
    in numpy; where the single mode runs in Dr.Jit (LLVM or CUDA variants) the lasers' own
    rays cost less than that (BENCHMARKS.md, "Laser ranging"), so only the numpy and scalar
    casters share.
    """
    if session is None:
        return True
    return not session.variant.startswith(("llvm", "cuda"))
