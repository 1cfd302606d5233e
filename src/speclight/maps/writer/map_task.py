"""One chunk of a reflectivity map as a task: plain data in, numpy arrays out.

:func:`render_map_chunk` runs where :mod:`speclight.scale` puts it (this process, or a Dask
worker): it receives only picklable data (the :class:`MapJob` shared by every chunk, the
:class:`MapChunk` of directions) and builds the target, the render session (its Mitsuba
scene) and the instrument kernel inside the task, once per process (:func:`map_engine`,
kept by :func:`speclight.scale.worker_cached`). It returns the chunk's arrays, already in the
store's float32; the calling process alone writes them into the Zarr store.

The target's files (meshes, spectra of materials, the instrument's curves) are read inside
the task, at the paths the scenario gives relative to its folder (``LoadedScenario.base_dir``):
a worker on another machine needs the same paths (a shared file system).
"""

from __future__ import annotations

import hashlib
import os
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.maps.writer.map_render import coaxial_returns, render_chunk
from speclight.scale import worker_cached
from speclight.scenario import LoadedScenario

F64 = NDArray[np.float64]
F32 = NDArray[np.float32]


@dataclass(frozen=True)
class MapEngine:
    """What a process builds once per scenario: target, render session, instrument kernel."""

    target: Any
    session: Any
    kernel: Any


@dataclass(frozen=True)
class MapJob:
    """Everything a chunk needs besides its directions (the same for every chunk)."""

    loaded: LoadedScenario
    variant: str
    geoms: list[tuple[int, int, float, float]]
    shapes: dict[str, int]
    wavelength_nm: F64
    solar_W_m2_nm: F64
    edges_m: F64
    ranging: bool


@dataclass(frozen=True)
class MapChunk:
    """Chunk ``k``: directions ``lo:hi`` of the map (``dirs`` is that slice)."""

    k: int
    lo: int
    hi: int
    dirs: F64


def map_engine(loaded: LoadedScenario, variant: str | None) -> MapEngine:
    """The scenario's target, render session and instrument kernel, built once per process.

    Keyed by the scenario text's SHA-256, its folder (relative file paths), the render mode
    and the variant; an engine built for ``auto`` is kept under the variant it chose too.
    """
    sc = loaded.scenario

    def key(v: str | None) -> str:
        text = hashlib.sha256(loaded.yaml_text.encode()).hexdigest()
        return f"reflectivity-map:{text}:{loaded.base_dir}:{sc.render.mode}:{v or 'auto'}"

    engine = worker_cached(key(variant), lambda: _build(loaded, variant))
    worker_cached(key(engine.session.variant), lambda: engine)
    return engine


def _build(loaded: LoadedScenario, variant: str | None) -> MapEngine:
    from speclight.render import RenderSession
    from speclight.simulation.radiometry import instrument_response, wavelength_grid_nm
    from speclight.simulation.reflection import build_target

    sc = loaded.scenario
    target = build_target(loaded)
    session = RenderSession.create(sc.render.mode, variant, target.materials)
    wl = wavelength_grid_nm(sc.spectrum)
    kernel = instrument_response(
        loaded, wl, np.zeros((1, wl.size)), np.ones((1, wl.size)), np.ones(1)
    )
    return MapEngine(target, session, kernel)


def render_map_chunk(job: MapJob, chunk: MapChunk) -> dict[str, F32]:
    """The arrays of one chunk, by store array name, float32.

    ``intensity`` (n, P, R, L); ``count_rate`` (n, P, R, B) with bands; ``range_offset``
    (n, L) and, with bands, ``range_histogram`` (n, B, bins) for a ranging map.
    """
    engine = map_engine(job.loaded, job.variant)
    band_names = engine.kernel.band_names
    inten, rate = render_chunk(
        job.loaded,
        engine.target,
        engine.session,
        chunk.dirs,
        job.geoms,
        job.shapes,
        job.wavelength_nm,
        job.solar_W_m2_nm,
        engine.kernel,
        chunk.k,
        workers=os.cpu_count() or 1,  # numpy caster: this process's share (one in Dask)
    )
    out = {"intensity": inten.astype(np.float32)}
    if band_names:
        out["count_rate"] = rate.astype(np.float32)
    if job.ranging:
        offset, hist = coaxial_returns(
            engine.target,
            engine.session,
            chunk.dirs,
            job.wavelength_nm,
            job.loaded,
            engine.kernel,
            job.edges_m,
        )
        out["range_offset"] = offset.astype(np.float32)
        if band_names:
            out["range_histogram"] = hist.astype(np.float32)
    return out
