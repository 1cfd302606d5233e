"""Up-front limits of a run: its peak memory and its path-mode render time, from the scenario.

A run that cannot fit in memory is refused before any work, with the estimate, the limit and
the fields to reduce (issue 9), instead of dying with ``MemoryError`` hours later. The model
is linear in what the pipeline allocates (the coefficients measured as stated in
BENCHMARKS.md, "Memory"):

* a base: the process, Python, numpy, skyfield and Dr.Jit/LLVM loaded, :data:`BASE_BYTES`;
* per epoch: the geometry and flags, :data:`BYTES_PER_EPOCH` (a geometry-only run, without a
  target, allocates nothing per wavelength bin); with a target, per epoch and wavelength bin
  the (N, L) arrays (solar irradiance, transmission, intensity, its standard error and the
  spectral flux) with their copies in the dataset and the in-memory file,
  :data:`BYTES_PER_EPOCH_BIN` and :data:`BYTES_PER_RENDERED_EPOCH_BIN`; per epoch and band the
  count rates and magnitudes, :data:`BYTES_PER_EPOCH_BAND`;
* per ray of one render batch (single mode: at least one epoch, up to
  :data:`~speclight.render.material_channels.RAYS_PER_BATCH` rays), :data:`BYTES_PER_RAY`;
  path mode renders one epoch at a time, on :data:`PATH_BASE_BYTES` more;
* single mode, per epoch and render channel (one per material, ``PLASTIC_NODES**2`` more per
  ``plastic``, a file's wavelength nodes per RGL material: :func:`channel_count`, the
  layout of :class:`speclight.render.material_channels.ChannelLayout`) the channel weights
  ``w`` (N, C) of :func:`speclight.render.single.geometric_weights`, float64, and per batch
  epoch its two (batch, C) temporaries, :data:`BYTES_PER_EPOCH_CHANNEL`; per epoch, material
  and bin the materials' spectral factors (N, L), :data:`BYTES_PER_EPOCH_MATERIAL_FACTOR_BIN`
  (counted from the allocations: a box-wing, 3 plastics, has 3,271 channels, 26 kB per
  epoch);
* per saved image: its radiance (float64 in the render, float32 in the dataset), depth and
  part maps, :data:`BYTES_PER_IMAGE_PIXEL_BIN` per pixel and bin;
* with lasers: per epoch the range histograms (band x range bin, float64, accumulated and
  stored) and each laser's spectral intensity;
* with ``render.per_material``: per epoch, material and bin the shares (N, M, L) of
  :mod:`speclight.simulation.per_material` (the render's output and the accumulated shares,
  float64), and per epoch, material and band the factors and their file copy,
  :data:`BYTES_PER_EPOCH_MATERIAL_BIN` and :data:`BYTES_PER_EPOCH_MATERIAL_BAND` (counted
  from the allocations, not measured).

Every term is an upper bound in the count of rendered epochs (all epochs are assumed lit).
The limit is :data:`MEMORY_FRACTION` of the machine's physical memory (``os.sysconf``), or
the process's address-space limit (``RLIMIT_AS``) where that is lower.
"""

from __future__ import annotations

import math
import os
import resource
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from speclight.errors import InputError
from speclight.scenario import LoadedScenario
from speclight.scenario.scenario_model import Scenario
from speclight.scenario.sections_light import PATH_SAMPLES_PER_S, PATH_SECONDS_PER_EPOCH

MIB = 1024**2
#: Peak of a run of a few epochs at small resolution, above the pixel term (measured).
BASE_BYTES = 230 * MIB
#: Geometry, attitude, pointing (RA/Dec, rates, the Sun's elevation) and flags of one epoch,
#: dataset and file copies included (measured: geometry-only runs of 2e5 and 2e6 epochs,
#: 1.50 KB per epoch between them) [bytes].
BYTES_PER_EPOCH = 1550
#: Solar irradiance and transmission (N, L) of a run with a target, per epoch and bin
#: (measured before geometry-only runs stopped writing them: 941 vs 189 bins) [bytes].
BYTES_PER_EPOCH_BIN = 21
#: (N, L) arrays added by a target: intensity, intensity_std, spectral_flux, float64, each
#: held twice (the stage's array and the dataset's, then the file) [bytes].
BYTES_PER_RENDERED_EPOCH_BIN = 3 * 8 * 2
#: (N, B) count_rate, count_rate_measured, ab_magnitude, ab_magnitude_exo and
#: ab_magnitude_standard, and their file copies [bytes].
BYTES_PER_EPOCH_BAND = 5 * 8 * 2
#: One primary ray of a single-mode batch with its hits, shadow rays and channel weights
#: (measured: 1024 and 2048 px) [bytes].
BYTES_PER_RAY = 341
#: Single mode: one channel weight per epoch (float64, ``w`` of
#: :func:`speclight.render.single.geometric_weights`) [bytes].
BYTES_PER_EPOCH_CHANNEL = 8
#: Single mode: a batch's weights as counted (``np.bincount``) and scaled by the pixel area,
#: both (batch, C) float64 [bytes per batch epoch and channel].
BYTES_PER_BATCH_EPOCH_CHANNEL = 2 * 8
#: Single mode: each material's spectral factor (N, L), float64 [bytes].
BYTES_PER_EPOCH_MATERIAL_FACTOR_BIN = 8
#: Path mode's extra base: Mitsuba's spectral variant and scene (measured: a first path run
#: at 128 px peaked at 1137 MiB; its memory did not grow with spp, 64 to 1024) [bytes].
PATH_BASE_BYTES = 900 * MIB
#: A saved image per pixel and bin: float64 in the render, float32 in the dataset [bytes].
BYTES_PER_IMAGE_PIXEL_BIN = 8 + 4
#: Laser range histograms per epoch, band and range bin: accumulator and stored [bytes].
BYTES_PER_EPOCH_BAND_RANGE_BIN = 8 * 2
#: render.per_material: the (N, M, L) render output and accumulated shares, float64 [bytes].
BYTES_PER_EPOCH_MATERIAL_BIN = 2 * 8
#: render.per_material: the (N, M, B) factors, Sun and lasers, and their file copies [bytes].
BYTES_PER_EPOCH_MATERIAL_BAND = 2 * 8 * 2
#: Fraction of the physical memory a run may plan to use: the rest stays for the system and
#: for the transients the model does not count (allocator slack, Dr.Jit's arenas).
MEMORY_FRACTION = 0.5
#: Longest estimated path-mode render accepted [s]: one day. The output is written only at
#: the end, so a longer run risks losing everything to one interruption: split the window.
MAX_PATH_RENDER_S = 86_400.0


@dataclass(frozen=True)
class MemoryEstimate:
    """A run's estimated peak memory [bytes] and its parts (name -> bytes)."""

    total_bytes: int
    parts: dict[str, int]


def grid_epochs(scenario: Scenario) -> int:
    """Epochs of the scenario's time grid (the count of
    :func:`speclight.simulation.geometry_stage.time_grid`, without building it)."""
    grid = scenario.time
    span_s = (grid.stop - grid.start).total_seconds()
    return math.floor(span_s / grid.step_s + 1e-9) + 1


def _bins(scenario: Scenario) -> int:
    sp = scenario.spectrum
    return math.floor((sp.max_nm - sp.min_nm) / sp.step_nm + 1e-9) + 1


def channel_count(scenario: Scenario, resolve: Callable[[str], Path] | None = None) -> int:
    """Render channels of the scenario's target in single mode: one per material, plus its
    block (:func:`speclight.render.bsdfs.planned_channels`: ``PLASTIC_NODES**2`` per
    ``plastic`` and the wavelength nodes of each RGL file, read through ``resolve``, a
    relative path to a file; 0 where it cannot be read: the run reports that file itself).
    0 without a target."""
    from speclight.render.bsdfs import planned_channels

    if scenario.target is None:
        return 0
    return sum(planned_channels(m, resolve) for m in scenario.target.materials.values())


def estimate_memory(
    scenario: Scenario, n_epochs: int, resolve: Callable[[str], Path] | None = None
) -> MemoryEstimate:
    """The peak memory of a run of ``scenario`` at ``n_epochs`` epochs (model above).

    ``resolve`` turns a file name of the scenario into a path (``LoadedScenario.resolve``):
    RGL material files give their channel count.
    """
    from speclight.ranging.bins import RANGE_BINS
    from speclight.render.material_channels import RAYS_PER_BATCH

    n, n_bin = int(n_epochs), _bins(scenario)
    n_band = len(scenario.instrument.bands)
    parts = {
        "base": BASE_BYTES,
        "epochs": n * BYTES_PER_EPOCH,
        "bins": n_bin * 8 * (8 + 3 * n_band),  # grids, solar spectrum, band curves
    }
    if scenario.target is not None:
        render = scenario.render
        pixels = render.resolution_px**2
        per_epoch = n_bin * (BYTES_PER_EPOCH_BIN + BYTES_PER_RENDERED_EPOCH_BIN)
        per_epoch += n_band * BYTES_PER_EPOCH_BAND
        parts["spectra"] = n * per_epoch
        if render.mode == "single":
            epochs_per_batch = max(1, min(n, RAYS_PER_BATCH // pixels))
            parts["render batch"] = epochs_per_batch * pixels * BYTES_PER_RAY
            # RGL materials make batches smaller (rays_per_batch): this one is an upper bound
            n_channel = channel_count(scenario, resolve)
            parts["channels"] = n_channel * (
                n * BYTES_PER_EPOCH_CHANNEL + epochs_per_batch * BYTES_PER_BATCH_EPOCH_CHANNEL
            )
            n_mat = len(scenario.target.materials)
            parts["channels"] += n * n_mat * n_bin * BYTES_PER_EPOCH_MATERIAL_FACTOR_BIN
        else:
            parts["render batch"] = PATH_BASE_BYTES + pixels * BYTES_PER_RAY
        images = len(set(render.save_images_at))
        parts["images"] = images * pixels * (n_bin * BYTES_PER_IMAGE_PIXEL_BIN + 16)
        if render.per_material:
            n_mat = len(scenario.target.materials)
            parts["per material"] = (
                n
                * n_mat
                * (n_bin * BYTES_PER_EPOCH_MATERIAL_BIN + n_band * BYTES_PER_EPOCH_MATERIAL_BAND)
            )
        lasers = len(scenario.illumination.lasers)
        if lasers:
            range_bins = RANGE_BINS * (2 if render.mode == "path" else 1)
            parts["lasers"] = n * (
                n_band * range_bins * BYTES_PER_EPOCH_BAND_RANGE_BIN + lasers * n_bin * 8 * 2
            )
    return MemoryEstimate(sum(parts.values()), parts)


def memory_limit_bytes() -> int:
    """The default limit: :data:`MEMORY_FRACTION` of the physical memory, or the process's
    address-space limit (``RLIMIT_AS``) where lower."""
    physical = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    limit = int(MEMORY_FRACTION * physical)
    soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    if soft != resource.RLIM_INFINITY:
        limit = min(limit, int(soft))
    return limit


def path_render_seconds(scenario: Scenario, n_epochs: int) -> float:
    """Estimated path-mode render time [s]: per epoch :data:`PATH_SECONDS_PER_EPOCH` plus
    pixels x spp / :data:`PATH_SAMPLES_PER_S` (measured on the box-wing, BENCHMARKS.md
    "Path mode"; targets that fill more of the view, or bounce light more, take longer)."""
    render = scenario.render
    samples = render.resolution_px**2 * render.samples_per_pixel
    return n_epochs * (PATH_SECONDS_PER_EPOCH + samples / PATH_SAMPLES_PER_S)


def path_render_note(scenario: Scenario, n_epochs: int) -> str:
    """The one-line up-front estimate shown before a path-mode render."""
    r = scenario.render
    seconds = path_render_seconds(scenario, n_epochs)
    shown = f"{seconds:.0f} s" if seconds < 120 else f"{seconds / 60:.1f} min"
    return (
        f"path mode: {n_epochs} epochs x {r.resolution_px} px x {r.samples_per_pixel} spp, "
        f"about {shown} to render"
    )


def _gib(n: float) -> str:
    return f"{n / 1024**3:.3g} GiB"


def check_run_limits(
    loaded: LoadedScenario, n_epochs: int, limit_bytes: int | None = None
) -> MemoryEstimate:
    """Refuse a run whose estimated peak memory exceeds the limit, or whose path-mode render
    would take longer than :data:`MAX_PATH_RENDER_S`, before any work.

    Parameters
    ----------
    loaded
        The validated scenario.
    n_epochs
        Epochs the run will compute (the time grid's, or those given).
    limit_bytes
        The limit [bytes]; default :func:`memory_limit_bytes`.

    Returns
    -------
    MemoryEstimate
        The run's estimate (within the limit).

    Raises
    ------
    InputError
        With the estimate, its largest parts, the limit and the fields to reduce.
    """
    sc = loaded.scenario
    if sc.target is not None and sc.render.mode == "path":
        seconds = path_render_seconds(sc, n_epochs)
        if seconds > MAX_PATH_RENDER_S:
            raise InputError(
                f"path mode at {sc.render.resolution_px} px x {sc.render.samples_per_pixel} spp "
                f"x {n_epochs} epochs would render for about {seconds / 3600:.3g} h "
                f"({PATH_SAMPLES_PER_S:.2g} samples/s); accepted: at most "
                f"{MAX_PATH_RENDER_S / 3600:g} h per run: reduce render.samples_per_pixel or "
                "render.resolution_px, or split the time window into several runs",
                source=loaded.source,
                field="render.samples_per_pixel",
            )
    limit = memory_limit_bytes() if limit_bytes is None else int(limit_bytes)
    est = estimate_memory(loaded.scenario, n_epochs, loaded.resolve)
    if est.total_bytes <= limit:
        return est
    largest = sorted(est.parts.items(), key=lambda kv: -kv[1])[:3]
    shown = ", ".join(f"{k} {_gib(v)}" for k, v in largest)
    fields = ["time (fewer epochs: a larger step_s or a shorter window)", "spectrum.step_nm"]
    if loaded.scenario.target is not None:
        fields += ["render.resolution_px", "render.save_images_at"]
        if loaded.scenario.render.mode == "path":
            fields.append("render.samples_per_pixel")
    raise InputError(
        f"this run needs about {_gib(est.total_bytes)} of memory ({n_epochs} epochs x "
        f"{_bins(loaded.scenario)} bins; largest parts: {shown}), more than the limit of "
        f"{_gib(limit)} ({MEMORY_FRACTION:g} of the physical memory, or the process limit); "
        f"reduce {', '.join(fields)}",
        source=loaded.source,
        field="time",
    )


__all__ = [
    "MemoryEstimate",
    "check_run_limits",
    "estimate_memory",
    "grid_epochs",
    "memory_limit_bytes",
    "path_render_note",
    "path_render_seconds",
]
