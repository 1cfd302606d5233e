"""The Zarr store of a reflectivity map as its writer sees it: parameters check, resume
bookkeeping (layout: :mod:`speclight.maps.map_format`)."""

from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.io import zarr_store_path
from speclight.io.store_io import readable
from speclight.maps.map_format import DATA_ARRAYS, DIMS, FORMAT_NAME

FIELD = "output"
TODO, DONE, FAILED = 0, 1, 2


def check_store_path(output: str | os.PathLike[str], inputs: dict[str, Path]) -> Path:
    """Refuse a store name that cannot be written (:mod:`speclight.io.zarr_store_path`)."""
    return zarr_store_path.check_store_path(output, inputs, example="map.zarr")


def open_or_create(
    path: Path,
    parameters: dict[str, Any],
    shapes: dict[str, int],
    chunk: int,
    force: bool,
) -> tuple[Any, bool]:
    """Open the store to resume it, or create it; ``(group, resumed)``.

    An existing store is resumed when its ``parameters`` equal ``parameters`` and it is not
    complete; a complete one, or one made with other parameters, is refused unless ``force``
    (which deletes it first). A store whose creation did not finish (an empty folder, or no
    ``parameters`` yet: :func:`mark_created` was not reached, e.g. on a full disk) holds no
    rendered chunk and is created again. The caller writes the coordinates and metadata of
    a new store, then calls :func:`mark_created`.

    Parameters
    ----------
    path
        The store (a folder).
    parameters
        What a resumed run must match (nside, phase angles, rolls, chunk, scenario hash).
    shapes
        The arrays' sizes (direction, phase, roll, wavelength, band, range_bin, ranging).
    chunk
        Directions per chunk.
    force
        Replace an existing map.
    """
    import zarr

    if path.exists() and not force and not _unfinished_creation(path):
        try:
            group = zarr.open_group(str(path), mode="r+")
            old: dict[str, Any] = dict(group.attrs.get("parameters", {}))  # type: ignore[arg-type]
            complete = bool(group.attrs.get("complete", False))
        except Exception as exc:  # not a Zarr group at all
            raise InputError(
                f"{path} exists and is not a speclight reflectivity map ({exc}); choose another "
                "name or pass force=True to replace it",
                field=FIELD,
            ) from None
        if complete:
            raise InputError(
                f"{path} exists and is complete; choose another name or pass force=True to "
                "render it again",
                field=FIELD,
            )
        if old != parameters:
            diff = sorted(k for k in set(old) | set(parameters) if old.get(k) != parameters.get(k))
            raise InputError(
                f"{path} is an unfinished map made with other parameters ({', '.join(diff)}); "
                "rerun with the same ones to resume it, or pass force=True to start again",
                field=FIELD,
            )
        return group, True
    if path.exists():  # force, or unfinished: replace a map, never another folder
        if any(path.iterdir()) and _format_of(path) != FORMAT_NAME:
            raise InputError(
                f"{path} is a folder but not a speclight reflectivity map; force=True replaces "
                "only maps: choose another name",
                field=FIELD,
            )
        shutil.rmtree(path)
    # the format first: a store cut short by a full disk is still known as a map
    group = zarr.open_group(
        str(path), mode="w", zarr_format=3, attributes={"format": FORMAT_NAME, "complete": False}
    )
    d, p, r = shapes["direction"], shapes["phase"], shapes["roll"]
    n_wl, n_band = shapes["wavelength"], shapes["band"]
    n_chunks = -(-d // chunk)
    group.create_array(
        "intensity",
        shape=(d, p, r, n_wl),
        chunks=(chunk, p, r, n_wl),
        dtype="f4",
        fill_value=np.nan,
        dimension_names=DIMS["intensity"],
    )
    if n_band:
        group.create_array(
            "count_rate",
            shape=(d, p, r, n_band),
            chunks=(chunk, p, r, n_band),
            dtype="f4",
            fill_value=np.nan,
            dimension_names=DIMS["count_rate"],
        )
    if shapes.get("ranging"):
        group.create_array(
            "range_offset",
            shape=(d, n_wl),
            chunks=(chunk, n_wl),
            dtype="f4",
            fill_value=np.nan,
            dimension_names=DIMS["range_offset"],
        )
        if n_band:
            n_bins = shapes["range_bin"]
            group.create_array(
                "range_histogram",
                shape=(d, n_band, n_bins),
                chunks=(chunk, n_band, n_bins),
                dtype="f4",
                fill_value=np.nan,
                dimension_names=DIMS["range_histogram"],
            )
    group.create_array(
        "chunk_state",
        shape=(n_chunks,),
        chunks=(n_chunks,),
        dtype="u1",
        fill_value=0,
        dimension_names=DIMS["chunk_state"],
    )
    return group, False


def mark_created(group: Any, parameters: dict[str, Any]) -> None:
    """Record the ``parameters`` of a new store, last: from now on it is resumed."""
    group.attrs["parameters"] = parameters


def _unfinished_creation(path: Path) -> bool:
    """An empty folder, or a map store without ``parameters`` (see :func:`open_or_create`)."""
    import json

    if not path.is_dir():
        return False
    if not any(path.iterdir()):
        return True
    try:
        attrs = json.loads((path / "zarr.json").read_text()).get("attributes", {})
    except (OSError, ValueError, AttributeError):
        return False
    return attrs.get("format") == FORMAT_NAME and "parameters" not in attrs


def write_coordinates(group: Any, coords: dict[str, NDArray[Any]]) -> None:
    """Write the coordinate arrays (small, one chunk each)."""
    for name, values in coords.items():
        values = np.asarray(values, dtype=float)
        arr = group.create_array(
            name,
            shape=values.shape,
            chunks=values.shape,
            dtype="f8",
            overwrite=True,
            dimension_names=DIMS.get(name),
        )
        arr[...] = values


def chunk_states(group: Any) -> NDArray[np.uint8]:
    """The per-chunk state array (0 to do, 1 done, 2 failed)."""
    return np.asarray(group["chunk_state"][...], dtype=np.uint8)


def mark(group: Any, k: int, state: int, message: str | None = None) -> None:
    """Record chunk ``k`` as done or failed (with its message)."""
    failed: dict[str, Any] = dict(group.attrs.get("failed_chunks", {}))
    if state == FAILED:
        failed[str(k)] = message or "failed"
    else:
        failed.pop(str(k), None)
    group.attrs["failed_chunks"] = failed
    group["chunk_state"][k] = state


def damaged_chunks(group: Any, states: NDArray[np.uint8], chunk: int) -> list[int]:
    """Chunks marked done whose data do not read back (:func:`speclight.io.store_io.
    readable`: a chunk file cut short or deleted); the caller renders them again."""
    arrays = [group[name] for name in DATA_ARRAYS if name in group]
    return [
        k
        for k in np.flatnonzero(states == DONE).tolist()
        if not readable(arrays, slice(k * chunk, (k + 1) * chunk), complete="intensity")
    ]


def _format_of(path: Path) -> str | None:
    """The ``format`` attribute of the Zarr group at ``path`` (``None`` if it is none)."""
    import json

    try:
        meta = json.loads((path / "zarr.json").read_text())
        return str(meta.get("attributes", {}).get("format"))
    except (OSError, ValueError, AttributeError):
        return None
