"""Up-front limits of a reflectivity map: a chunk's memory, the store's size, the rolls.

A chunk of ``n`` directions renders ``n x G`` geometries at once (``G``: phase angles x
rolls, phase 0 once), in one process: its peak memory is that of a ``simulate`` run of as
many epochs (:func:`speclight.simulation.memory.estimate_memory`: render batch, channel
weights, spectra). A chunk that cannot fit under the memory limit is refused before any
work, with the largest chunk that fits; the workers of a local cluster, each rendering one
chunk, are as many as fit (:func:`speclight.scale.executor.local_workers`). The store's
data, uncompressed, must fit on its disk (:func:`speclight.io.store_io.check_free_space`).
"""

from __future__ import annotations

from speclight.errors import InputError
from speclight.scenario import LoadedScenario
from speclight.simulation.memory import estimate_memory, memory_limit_bytes

#: Most rolls of the Sun-observer plane: one per degree.
MAX_ROLLS = 360
#: Bytes per stored value (float32).
VALUE_BYTES = 4


def chunk_bytes(loaded: LoadedScenario, chunk: int, n_geometries: int) -> int:
    """Estimated peak memory [bytes] of rendering one chunk of ``chunk`` directions."""
    return estimate_memory(loaded.scenario, chunk * n_geometries, loaded.resolve).total_bytes


def check_chunk_memory(
    loaded: LoadedScenario,
    chunk: int,
    n_geometries: int,
    limit_bytes: int | None = None,
    asked: int | None = None,
) -> int:
    """The peak memory of one chunk [bytes]; refuse a chunk above the limit, naming the
    largest that fits.

    Parameters
    ----------
    loaded
        The scenario (render settings and spectrum set the cost of a geometry).
    chunk
        Directions per chunk, cut to the map's directions.
    n_geometries
        Geometries rendered per direction (phase angles x rolls, phase 0 once).
    limit_bytes
        The limit [bytes] (default
        :func:`~speclight.simulation.memory.memory_limit_bytes`).
    asked
        The chunk the user gave, for the message (default ``chunk``).
    """
    limit = memory_limit_bytes() if limit_bytes is None else int(limit_bytes)
    need = chunk_bytes(loaded, chunk, n_geometries)
    if need <= limit:
        return need
    fits, too_many = 0, chunk  # bisection: the estimate grows with the chunk
    while too_many - fits > 1:
        mid = (fits + too_many) // 2
        if chunk_bytes(loaded, mid, n_geometries) <= limit:
            fits = mid
        else:
            too_many = mid
    accepted = f"at most {fits} for this map" if fits else "none: fewer phase angles x rolls"
    raise InputError(
        f"chunk = {asked or chunk}: a chunk renders {chunk} directions x {n_geometries} "
        f"geometries = {chunk * n_geometries} at once, about {need / 1024**3:.3g} GiB of "
        f"memory, more than the limit of {limit / 1024**3:.3g} GiB (half the physical "
        f"memory, or the process limit); accepted: {accepted} (render.resolution_px and "
        "spectrum.step_nm set the cost of each geometry)",
        field="chunk",
    )


def store_bytes(shapes: dict[str, int]) -> int:
    """The store's data arrays, uncompressed [bytes] (layout: :mod:`speclight.maps.map_format`)."""
    d, p, r = shapes["direction"], shapes["phase"], shapes["roll"]
    n_wl, n_band = shapes["wavelength"], shapes["band"]
    values = d * p * r * (n_wl + n_band)
    if shapes.get("ranging"):
        values += d * (n_wl + n_band * shapes["range_bin"])
    return values * VALUE_BYTES


def check_rolls(rolls: int) -> None:
    """Refuse rolls outside 1..:data:`MAX_ROLLS`."""
    if not 1 <= int(rolls) <= MAX_ROLLS:
        raise InputError(
            f"rolls = {rolls} must be in 1..{MAX_ROLLS} (one roll per degree at most)",
            field="rolls",
        )
