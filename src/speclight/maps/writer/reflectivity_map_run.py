"""Reflectivity maps: the target rendered for many body-frame geometries, in a Zarr store.

:func:`reflectivity_map` renders the scenario's target (its materials, spectrum, render
settings and bands) for every HEALPix phase-vector direction x phase angle x roll
(conventions: :mod:`speclight.maps.map_geometry`) and streams the results, chunk by chunk
of directions, into a resumable store (layout: :mod:`speclight.maps.map_format`). Each chunk is
a task of :mod:`speclight.scale` (in this process, or on a Dask cluster:
:mod:`.map_task`); this process alone writes the store, as chunks finish.
``render: {mode: map, map_file: MAP.zarr}`` then interpolates the map instead of rendering
(:mod:`speclight.maps.map_lookup`).
"""

from __future__ import annotations

import functools
import hashlib
import os
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.io.store_io import check_free_space, store_lock, store_writes
from speclight.maps.map_geometry import healpix_directions, nside_for
from speclight.maps.writer import map_store as store
from speclight.maps.writer.map_limits import check_chunk_memory, check_rolls, store_bytes
from speclight.maps.writer.map_task import MapChunk, MapJob, map_engine, render_map_chunk
from speclight.ranging.bins import range_bin_edges_m
from speclight.scale import Outcome, open_executor
from speclight.scenario import LoadedScenario

F64 = NDArray[np.float64]
#: Directions per chunk by default: 512 x 25 geometries x 189 bins x 8 B = 19 MB of
#: intensity per chunk (passive map of 4 phase angles x 8 rolls).
DEFAULT_CHUNK = 512
#: Largest phase angle of a map [deg]: at 180 deg there is no phase vector.
MAX_PHASE_ANGLE_DEG = 179.0


@dataclass
class MapRun:
    """What a :func:`reflectivity_map` run did."""

    path: Path
    n_directions: int
    n_chunks: int
    rendered: int
    skipped: int
    failed: dict[str, str] = field(default_factory=dict)
    complete: bool = False
    seconds: float = 0.0
    #: Chunks marked done that did not read back (a chunk file cut short): rendered again.
    damaged: list[int] = field(default_factory=list)


def check_map_options(
    *,
    directions: int,
    phase_angles_deg: Sequence[float],
    rolls: int,
    chunk: int,
    n_workers: int | None = None,
) -> tuple[int, list[float], int]:
    """Validate the options; return ``(nside, sorted phase angles, stored rolls)``.

    Parameters
    ----------
    directions
        At least this many phase-vector directions (>= 12).
    phase_angles_deg
        Phase angles [deg], 0..179, none twice.
    rolls
        Rolls of the Sun-observer plane, 1..360.
    chunk
        Directions per chunk, >= 1.
    n_workers
        Workers of a local cluster, >= 1, or None.
    """
    nside = nside_for(directions)
    angles = [float(a) for a in phase_angles_deg]
    if not angles or not all(np.isfinite(angles)):
        raise InputError(
            f"phase_angles_deg = {phase_angles_deg} must be one or more numbers",
            field="phase_angles_deg",
        )
    if min(angles) < 0 or max(angles) > MAX_PHASE_ANGLE_DEG:
        raise InputError(
            f"phase_angles_deg = {phase_angles_deg}: each must be in 0..{MAX_PHASE_ANGLE_DEG:g}",
            field="phase_angles_deg",
        )
    if len(set(angles)) != len(angles):
        raise InputError(
            f"phase_angles_deg = {phase_angles_deg} repeats an angle", field="phase_angles_deg"
        )
    check_rolls(rolls)
    if int(chunk) < 1:
        raise InputError(f"chunk = {chunk} must be >= 1", field="chunk")
    if n_workers is not None and int(n_workers) < 1:
        raise InputError(f"n_workers = {n_workers} must be >= 1", field="n_workers")
    stored_rolls = 1 if all(a == 0 for a in angles) else int(rolls)
    return nside, sorted(angles), stored_rolls


def _geometries(angles: list[float], n_rolls: int) -> list[tuple[int, int, float, float]]:
    """(phase index, roll index, phase [rad], roll [rad]) rendered per direction; phase 0
    once (roll 0), copied to every roll."""
    out = []
    for j, a in enumerate(angles):
        for k in range(1 if a == 0 else n_rolls):
            out.append((j, k, np.radians(a), 2 * np.pi * k / n_rolls))
    return out


def reflectivity_map(
    loaded: LoadedScenario,
    output: str | os.PathLike[str],
    *,
    directions: int = 10_000,
    phase_angles_deg: Sequence[float] = (0.0,),
    rolls: int = 8,
    chunk: int = DEFAULT_CHUNK,
    force: bool = False,
    progress: bool = False,
    max_chunks: int | None = None,
    scheduler: str | None = "none",
    n_workers: int | None = None,
    announce: bool = False,
) -> MapRun:
    """Render the scenario's target into a reflectivity map (docs/reflectivity-map.md).

    Parameters
    ----------
    loaded
        Scenario: target, materials, spectrum, render settings (single or path), bands.
    output
        The Zarr store (a folder). An unfinished store made with the same parameters is
        resumed (done chunks are skipped, failed ones retried).
    directions
        At least this many phase-vector directions (HEALPix, the next power-of-two nside).
    phase_angles_deg
        Phase angles [deg], 0 (coaxial, e.g. a laser) to 179.
    rolls
        Rolls of the Sun-observer plane about the phase vector, evenly over 360 deg (one
        is stored when every phase angle is 0).
    chunk
        Directions per chunk (the unit of work, of resume and of memory).
    force
        Replace an existing store.
    progress
        Show a progress bar over chunks on a terminal.
    max_chunks
        Render at most this many chunks in this call (the rest stay to do: resume later).
    scheduler
        Where the chunks are rendered (:func:`speclight.scale.open_executor`): ``none`` (in
        this process, the default of this function), ``local`` (a new local Dask cluster)
        or the address of a running Dask scheduler. The result is the same, bit for bit.
    n_workers
        Workers of a local cluster (default: the cores).
    announce
        Print where the chunks run and the Dask dashboard address on stderr.

    Returns
    -------
    MapRun
        Counts, failed chunks (index -> message) and whether the map is complete.
    """
    sc = loaded.scenario
    if sc.target is None:
        raise InputError("a reflectivity map needs a target section", field="target")
    if sc.render.mode not in ("single", "path"):
        raise InputError(
            f"render.mode = '{sc.render.mode}': a map is rendered in mode single or path",
            field="render.mode",
        )
    nside, angles, n_rolls = check_map_options(
        directions=directions, phase_angles_deg=phase_angles_deg, rolls=rolls, chunk=chunk,
        n_workers=n_workers,
    )  # fmt: skip
    path = store.check_store_path(output, {"scenario file": Path(loaded.source)})
    from speclight.illumination import solar_irradiance_W_m2_nm
    from speclight.simulation.radiometry import wavelength_grid_nm

    dirs = healpix_directions(nside)
    size = min(int(chunk), len(dirs))  # a chunk larger than the map is the whole map
    n_geoms = sum(1 if a == 0 else n_rolls for a in angles)  # as _geometries lists them
    task_bytes = check_chunk_memory(loaded, size, n_geoms, asked=int(chunk))  # up front
    geoms = _geometries(angles, n_rolls)
    engine = map_engine(loaded, sc.render.variant)  # also the serial run's (cached)
    band_names = engine.kernel.band_names
    wl = wavelength_grid_nm(sc.spectrum)
    parameters = {
        "healpix_nside": nside,
        "phase_angle_deg": angles,
        "rolls": n_rolls,
        "chunk": size,
        "scenario_sha256": hashlib.sha256(loaded.yaml_text.encode()).hexdigest(),
    }
    ranging = bool(sc.illumination.lasers) and 0.0 in angles
    # single-bounce bins about the body origin (the map's centre of mass), as in simulate
    edges = range_bin_edges_m(engine.target, np.zeros(3))
    shapes = {
        "ranging": int(ranging),
        "direction": len(dirs),
        "phase": len(angles),
        "roll": n_rolls,
        "wavelength": wl.size,
        "band": len(band_names),
        "range_bin": len(edges) - 1,
    }
    job = MapJob(
        loaded,
        engine.session.variant,
        geoms,
        shapes,
        wl,
        solar_irradiance_W_m2_nm(wl, 1.0),
        edges,
        ranging,
    )
    started = time.perf_counter()
    with store_lock(path):
        with store_writes(path):
            group, resumed = store.open_or_create(path, parameters, shapes, size, force)
            if not resumed:
                _write_header(group, loaded, job, dirs, angles, band_names, nside)
                store.mark_created(group, parameters)
        states, damaged = _chunks_to_do(path, group, resumed, size)
        todo = [k for k in range(states.size) if states[k] != store.DONE]
        check_free_space(
            path, store_bytes(shapes) * len(todo) // states.size, "the map", "`directions`"
        )
        if max_chunks is not None:
            todo = todo[: max(int(max_chunks), 0)]
        run = MapRun(path, len(dirs), states.size, 0, int(np.sum(states == store.DONE)))
        run.damaged = damaged
        chunks = [
            MapChunk(k, k * size, min((k + 1) * size, len(dirs)), dirs[k * size : (k + 1) * size])
            for k in todo
        ]
        if chunks:
            with open_executor(
                scheduler, n_workers=n_workers, announce=announce, task_bytes=task_bytes
            ) as executor:
                task = functools.partial(render_map_chunk, job)
                for outcome in executor.run(
                    task, chunks, label="reflectivity map", progress=progress
                ):
                    with store_writes(path):
                        write_chunk(group, outcome)
                    if outcome.error is None:  # a failed chunk is counted in run.failed
                        run.rendered += 1
        states = store.chunk_states(group)
        run.failed = dict(group.attrs.get("failed_chunks", {}))
        run.complete = bool(np.all(states == store.DONE))
        with store_writes(path):
            group.attrs["complete"] = run.complete
    run.seconds = time.perf_counter() - started
    return run


def _write_header(
    group: Any,
    loaded: LoadedScenario,
    job: MapJob,
    dirs: F64,
    angles: list[float],
    band_names: list[str],
    nside: int,
) -> None:
    """A new store's coordinates and metadata."""
    from speclight.render import engine_versions

    n_rolls, edges = job.shapes["roll"], job.edges_m
    coords = {
        "direction_body": dirs,
        "phase_angle_deg": np.array(angles),
        "roll_deg": 360.0 * np.arange(n_rolls) / n_rolls,
        "wavelength": job.wavelength_nm,
    }
    if job.ranging and band_names:
        coords["range_bin"] = 0.5 * (edges[1:] + edges[:-1])
        coords["range_bin_bounds"] = np.stack([edges[:-1], edges[1:]], axis=1)
    store.write_coordinates(group, coords)
    group.attrs.update(_metadata(loaded, band_names, nside, job.variant))
    group.attrs["engine_versions"] = engine_versions()


def _chunks_to_do(
    path: Path, group: Any, resumed: bool, chunk: int
) -> tuple[NDArray[np.uint8], list[int]]:
    """The chunk states, with the done chunks of a resumed store that do not read back
    (damaged) set to do again; and those chunks."""
    lost = False
    try:
        states = store.chunk_states(group)
    except Exception:  # the state array itself is damaged: trust only data that reads back
        states = np.full(group["chunk_state"].shape[0], store.DONE, dtype=np.uint8)
        lost = True
    damaged = store.damaged_chunks(group, states, chunk) if resumed or lost else []
    states[damaged] = store.TODO
    if damaged or lost:
        with store_writes(path):
            group["chunk_state"][...] = states
    return states, damaged


def write_chunk(group: Any, outcome: Outcome[MapChunk, dict[str, Any]]) -> None:
    """Write one finished chunk's arrays into the store (its region) and mark it done, or
    mark it failed with the error text. Only the calling process writes the store."""
    c = outcome.item
    if outcome.result is None:
        store.mark(group, c.k, store.FAILED, outcome.error)
        return
    for name, values in outcome.result.items():
        group[name][c.lo : c.hi] = values
    store.mark(group, c.k, store.DONE)


def _metadata(
    loaded: LoadedScenario, band_names: list[str], nside: int, variant: str
) -> dict[str, Any]:
    from speclight import __version__

    sc = loaded.scenario
    assert sc.target is not None
    return {
        "healpix_nside": nside,
        "healpix_order": "ring",
        "band_names": band_names,
        "scenario_yaml": loaded.yaml_text,
        "scenario_source": loaded.source,
        "target": sc.target.model_dump(mode="json"),
        "render_mode": sc.render.mode,
        "render_variant": variant,
        "resolution_px": sc.render.resolution_px,
        "samples_per_pixel": sc.render.samples_per_pixel,
        "speclight_version": __version__,
        "units": {
            "intensity": "W sr-1 nm-1",
            "count_rate": "s-1",
            "range_offset": "m",
            "range_histogram": "s-1 per range bin",
            "range_bin": "m",
            "wavelength": "nm",
            "phase_angle_deg": "deg",
            "roll_deg": "deg",
        },
        "intensity_conditions": "the Sun at 1 AU (bin-averaged ASTM E490 spectrum), "
        "no Earth shadow",
        "count_rate_conditions": "range 1 m, aperture area 1 m2, no atmosphere "
        "(transmission 1); the scenario's optics transmission, detector QE and bands",
        "range_histogram_conditions": "phase angle 0: a coaxial laser of spectral "
        "irradiance 1 W m-2 nm-1 on every wavelength bin, single scattering; range 1 m, "
        "aperture area 1 m2, no atmosphere (transmission 1); the scenario's optics "
        "transmission, detector QE and bands; range offsets one-way from the body origin "
        "(the centre of mass), negative = in front",
        "conventions": "phase vector p = HEALPix RING pixel centre (body frame); roll r about "
        "p from e_lon = normalize(z x p) toward e_lat = p x e_lon; sun = cos(a/2) p + "
        "sin(a/2) u, observer = cos(a/2) p - sin(a/2) u, u = cos r e_lon + sin r e_lat",
        "failed_chunks": {},
    }
