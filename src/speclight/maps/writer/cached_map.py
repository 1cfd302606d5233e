"""A reflectivity map built from a scenario into the cache, found there on a rerun.

:func:`scenario_map` renders the scenario's target into a reflectivity map
(:func:`.reflectivity_map_run.reflectivity_map`, the writer of ``speclight
reflectivity-map``: the same store, the same renders) at a modest resolution
(:class:`MapResolution`: the scenario's ``render.resolution_px`` replaced), over the phase
angles asked for, and keeps it in the cache folder (:func:`speclight.cache.cache_root`,
``tumbling-maps/``) under a name made from a hash of what the map depends on: the scenario's
target, materials, spectrum, render settings, instrument and illumination (and the files
they name, by their SHA-256), the resolution and the phase angles. A rerun finds it there
and does not render again; an interrupted build resumes where it stopped (the writer's
resume). ``speclight shape --tumbling-starts N`` uses it for its light model
(:mod:`speclight.estimate.shape.tumbling_run`).

The default resolution, HEALPix nside 16 (3,072 phase-vector directions), 32 rolls, phase
angles every 10 deg and 64 px, is the one measured to be enough on speclight's own light
curves of the box-wing example made torque-free (``bench/bench_tumbling_map_resolution.py``,
BENCHMARKS.md "Tumbling: the map built from the scenario"): it has the smallest error at
the true state (chi-square 1,199 on 54 points, median relative error 3 %), and refitted
from the true state the fit stays in the truth's family (chi-square 906, moment ratios
0.463 and 0.799 for 0.45 and 0.80, rate +0.14 %). Coarser maps are not reliably so: nside
4 stayed (2,768), nside 8 left it (15,161, rate -15 %), its error at the truth (33,880)
mostly one point, most likely a glint of the wings (cover glass, roughness 0.05) that falls
between its nodes. The rolls (16 or 32) and the render (32 or 64 px) changed the error at
nside 8 little there; on the white box-wing the rolls mattered most (the shadows' edges).
The build took 431 s wall on 2 busy cores (786,432 renders, 368 MB in the cache); nside 8
82 s (71 MB), nside 4 26 s.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.maps.writer.reflectivity_map_run import MAX_PHASE_ANGLE_DEG, reflectivity_map
from speclight.scenario import LoadedScenario

F64 = NDArray[np.float64]
#: Sub-folder of the cache folder holding the built maps.
CACHE_KIND = "tumbling-maps"
#: Accepted values of :meth:`MapResolution.of_nside` (the HEALPix nside of the map).
MAP_NSIDES = (1, 2, 4, 8, 16)
#: Default of :meth:`MapResolution.of_nside` (the measured one, module doc).
DEFAULT_MAP_NSIDE = 16
#: Rolls, phase-angle step [deg] and render size [px] of :meth:`MapResolution.of_nside`.
DEFAULT_ROLLS, DEFAULT_PHASE_STEP_DEG, DEFAULT_RESOLUTION_PX = 32, 10.0, 64
#: Scenario sections a map depends on (the rest, time, orbit, attitude and site, not).
MAP_SECTIONS = ("target", "spectrum", "render", "instrument", "illumination")
#: Bumped when the way a map is built here changes (old cache entries are then not used).
BUILD_VERSION = 1


@dataclass(frozen=True)
class MapResolution:
    """Resolution of a map built from the scenario.

    Attributes
    ----------
    nside
        HEALPix nside of the phase-vector directions (``12 nside^2`` directions).
    rolls
        Rolls of the Sun-observer plane about the phase vector, evenly over 360 deg.
    phase_step_deg
        Step of the stored phase angles [deg] (multiples of it around the data's).
    resolution_px
        Pixels across each render (the scenario's ``render.resolution_px`` replaced).
    """

    nside: int
    rolls: int
    phase_step_deg: float
    resolution_px: int

    def __post_init__(self) -> None:
        if not (self.nside >= 1 and self.nside & (self.nside - 1) == 0):
            raise InputError(
                f"nside = {self.nside} must be a power of 2 (a HEALPix nside)", field="nside"
            )
        if not 0 < self.phase_step_deg <= MAX_PHASE_ANGLE_DEG:
            raise InputError(
                f"phase_step_deg = {self.phase_step_deg} must be in (0, {MAX_PHASE_ANGLE_DEG:g}]",
                field="phase_step_deg",
            )

    @classmethod
    def of_nside(cls, nside: int = DEFAULT_MAP_NSIDE) -> MapResolution:
        """HEALPix ``nside`` (``12 nside^2`` phase-vector directions) with
        :data:`DEFAULT_ROLLS` rolls, phase angles every :data:`DEFAULT_PHASE_STEP_DEG` deg
        and renders of :data:`DEFAULT_RESOLUTION_PX` px (module doc: the directions are what
        a glint needs, the rolls what the shadows need)."""
        if nside not in MAP_NSIDES:
            raise InputError(
                f"nside = {nside} is not accepted (a HEALPix nside: "
                f"{', '.join(map(str, MAP_NSIDES))})",
                field="nside",
            )
        return cls(nside, DEFAULT_ROLLS, DEFAULT_PHASE_STEP_DEG, DEFAULT_RESOLUTION_PX)

    def describe(self) -> str:
        """One line, e.g. ``HEALPix nside 8, 32 rolls, phase angles every 10 deg, 64 px``."""
        return (
            f"HEALPix nside {self.nside}, {self.rolls} rolls, phase angles every "
            f"{self.phase_step_deg:g} deg, {self.resolution_px} px"
        )


def map_phase_angles_deg(phase_angle_deg: F64, step_deg: float) -> list[float]:
    """Multiples of ``step_deg`` [deg] from below the smallest of ``phase_angle_deg`` to
    above the largest (the data's phase angles [deg]), the last at most 179 deg."""
    lo = math.floor(float(np.min(phase_angle_deg)) / step_deg) * step_deg
    hi = math.ceil(float(np.max(phase_angle_deg)) / step_deg) * step_deg
    angles = [
        min(lo + k * step_deg, MAX_PHASE_ANGLE_DEG) for k in range(round((hi - lo) / step_deg) + 1)
    ]
    return sorted(set(angles))


def map_cache_path(
    loaded: LoadedScenario,
    resolution: MapResolution,
    phase_angles_deg: list[float],
    cache_dir: Path | None = None,
) -> Path:
    """Where the map of ``loaded`` at ``resolution`` and ``phase_angles_deg`` is kept: the
    cache folder's ``tumbling-maps/<hash>.zarr`` (module doc)."""
    from speclight.cache import cache_root
    from speclight.simulation.input_hashes import input_files

    sc = loaded.scenario.model_dump(mode="json")
    files = {
        k: v["sha256"] for k, v in input_files(loaded).items() if k.split(".")[0] in MAP_SECTIONS
    }
    key = {
        "build_version": BUILD_VERSION,
        "sections": {name: sc.get(name) for name in MAP_SECTIONS},
        "files": files,
        "resolution": [resolution.nside, resolution.rolls, resolution.resolution_px],
        "phase_angle_deg": phase_angles_deg,
    }
    digest = hashlib.sha256(json.dumps(key, sort_keys=True, default=str).encode()).hexdigest()
    return cache_root(cache_dir) / CACHE_KIND / f"{digest[:32]}.zarr"


@dataclass(frozen=True)
class ScenarioMap:
    """A map of the scenario's target: its ``path``, whether this call ``built`` it (else it
    was found in the cache), its ``resolution``, phase angles [deg] and build time [s]."""

    path: Path
    built: bool
    resolution: MapResolution
    phase_angle_deg: list[float]
    seconds: float


def scenario_map(
    loaded: LoadedScenario,
    phase_angle_deg: F64,
    resolution: MapResolution | None = None,
    *,
    cache_dir: Path | None = None,
    progress: bool = False,
    say: Callable[[str], None] | None = None,
) -> ScenarioMap:
    """The reflectivity map of ``loaded``'s target covering ``phase_angle_deg`` [deg], from
    the cache or built there (module doc).

    Parameters
    ----------
    loaded
        The scenario of the light curves (target, materials, spectrum, render, bands).
    phase_angle_deg
        The phase angles to cover [deg] (e.g. the light curves'): the map stores multiples
        of the resolution's step around them.
    resolution
        The map's resolution (default :meth:`MapResolution.of_nside`).
    cache_dir
        The cache folder (default :func:`speclight.cache.cache_root`).
    progress
        Show the writer's progress over chunks.
    say
        Called with one line before a build (what, where, how many renders) and after it.
    """
    from speclight.maps.map_lookup import read_header
    from speclight.scenario.overrides import with_overrides

    res = resolution if resolution is not None else MapResolution.of_nside()
    angles = map_phase_angles_deg(phase_angle_deg, res.phase_step_deg)
    map_loaded = with_overrides(loaded, {"render.resolution_px": res.resolution_px})
    path = map_cache_path(map_loaded, res, angles, cache_dir)
    try:
        read_header(path)  # complete: reuse it
        return ScenarioMap(path, False, res, angles, 0.0)
    except InputError:
        pass  # missing or unfinished: build (an unfinished one resumes)
    n_dirs = 12 * res.nside**2
    renders = n_dirs * sum(1 if a == 0 else res.rolls for a in angles)
    if say is not None:
        say(
            f"building the reflectivity map of the scenario's target ({res.describe()}; "
            f"phase angles {angles[0]:g}-{angles[-1]:g} deg: {renders} renders) in {path}"
        )
    start = time.perf_counter()
    chunk = max(12, n_dirs // 16)  # about 16 chunks: progress and resume in steps
    common = dict(
        directions=n_dirs, phase_angles_deg=angles, rolls=res.rolls, chunk=chunk,
        progress=progress,
    )  # fmt: skip
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        run = reflectivity_map(map_loaded, path, **common)  # type: ignore[arg-type]
    except InputError:  # an unfinished store of another scenario text: start again
        run = reflectivity_map(map_loaded, path, force=True, **common)  # type: ignore[arg-type]
    if not run.complete:
        first = next(iter(run.failed.items()), ("?", "unknown"))
        raise InputError(
            f"the reflectivity map {path} is unfinished: {len(run.failed)} chunk(s) failed "
            f"(chunk {first[0]}: {first[1]}); run again to retry them",
            field="output",
        )
    seconds = time.perf_counter() - start
    if say is not None:
        say(f"built the reflectivity map in {seconds:.1f} s")
    return ScenarioMap(path, True, res, angles, seconds)
