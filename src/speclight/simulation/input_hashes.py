"""SHA-256 of every input file a run read, for the output's ``input_files`` attribute.

The scenario's YAML (kept in the output) names its files, but not what was in them: a TLE
file updated in place, an edited material table or a re-made reflectivity map would give
another result under the same YAML. The output therefore records, for every scenario field
that names a file, the resolved path and the SHA-256 of its bytes, and the same for the
Earth-orientation table the run used (``speclight update-data`` replaces it).

A folder (a reflectivity map's Zarr store) is hashed as the SHA-256 of the lines
``<relative path> <sha256 of the file>``, one per file in sorted order. Values that name a
table shipped with speclight (``detector_qe: sony-imx428-cmos``, a shipped BRDF table) are
not files of the user's: the ``speclight_version`` attribute identifies them. A mesh's side
files (an OBJ's ``.mtl``) are not named by the scenario and are not hashed.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from pydantic import BaseModel

from speclight.orbit.iers_files import finals_path
from speclight.orbit.orbit_sources import file_keys
from speclight.scenario import LoadedScenario
from speclight.target.bsdf_models import bsdf_file_parameters

#: Scenario fields (by their last name) whose string values may name a file or folder: the
#: orbit sources that read a file come from their registry
#: (:data:`speclight.orbit.orbit_sources.ORBIT_SOURCES`), so a new source is hashed too, and
#: the material parameters that name a file from the table of BSDF models
#: (:func:`speclight.target.bsdf_models.bsdf_file_parameters`).
FILE_FIELDS = frozenset(
    {
        "file",
        "mesh_file",
        "spectrum_file",
        "table_file",
        "map_file",
        "detector_qe",
        "optics_transmission",
    }
    | file_keys()
    | bsdf_file_parameters()
)
_CHUNK = 1 << 20


@functools.lru_cache(maxsize=256)
def _file_sha256(path: str, mtime_ns: int, size: int) -> str:
    """SHA-256 of a file; cached on its path, modification time and size (a fit's runs
    would otherwise hash the same files again and again)."""
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        while chunk := f.read(_CHUNK):
            digest.update(chunk)
    return digest.hexdigest()


def sha256_of(path: str | Path) -> str:
    """SHA-256 (hex) of a file, or of a folder's files (see the module docstring)."""
    p = Path(path)
    if p.is_dir():
        lines = []
        for folder, dirs, files in os.walk(p):
            dirs.sort()
            for name in sorted(files):
                f = Path(folder) / name
                lines.append(f"{f.relative_to(p).as_posix()} {sha256_of(f)}\n")
        return hashlib.sha256("".join(lines).encode()).hexdigest()
    st = p.stat()
    return _file_sha256(str(p.resolve()), st.st_mtime_ns, st.st_size)


def _walk(value: Any, where: str, named: bool) -> Iterator[tuple[str, str]]:
    """``(dotted field, text)`` of every string under a field that may name a file
    (``named``: the field's own name is one of :data:`FILE_FIELDS`)."""
    if isinstance(value, str):
        if named:
            yield where, value
    elif isinstance(value, list | tuple):
        for i, item in enumerate(value):
            yield from _walk(item, f"{where}.{i}", named)
    elif isinstance(value, BaseModel | dict):
        items = (
            value.items()
            if isinstance(value, dict)
            else ((k, getattr(value, k)) for k in type(value).model_fields)
        )
        for key, item in items:
            dotted = f"{where}.{key}" if where else str(key)
            yield from _walk(item, dotted, str(key) in FILE_FIELDS)


def input_files(loaded: LoadedScenario) -> dict[str, dict[str, str]]:
    """Every file the scenario names, and the Earth-orientation table, with their hashes.

    Returns
    -------
    dict
        ``{dotted scenario field: {"path": resolved path, "sha256": hex}}``, plus the key
        ``earth_orientation_table`` (``finals2000A.all``); fields whose value is not an
        existing file or folder (a shipped table's name, a number) are left out.
    """
    out: dict[str, dict[str, str]] = {}
    for field, text in _walk(loaded.scenario, "", False):
        path = loaded.resolve(text)
        try:
            exists = path.is_file() or path.is_dir()
        except (OSError, ValueError):  # not a path at all (a shipped table's name)
            exists = False
        if exists:
            out[field] = {"path": str(path.resolve()), "sha256": sha256_of(path)}
    finals = finals_path()
    if finals.is_file():
        out["earth_orientation_table"] = {"path": str(finals), "sha256": sha256_of(finals)}
    return out


def input_files_attribute(loaded: LoadedScenario) -> str:
    """:func:`input_files` as the JSON text of the ``input_files`` global attribute."""
    return json.dumps(input_files(loaded), sort_keys=True)
