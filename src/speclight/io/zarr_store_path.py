"""The one check of a Zarr store's name before any work (reflectivity maps, sweeps)."""

from __future__ import annotations

import os
from pathlib import Path

from speclight.errors import InputError

FIELD = "--output"


def check_store_path(
    output: str | os.PathLike[str], inputs: dict[str, Path], example: str = "out.zarr"
) -> Path:
    """Refuse a store name that cannot be written: empty, missing folder, a file, an input.

    ``inputs`` maps a role ("scenario file") to an input path the store must not be;
    ``example`` is the name suggested for an empty one.
    """
    text = os.fspath(output)
    if not text.strip():
        raise InputError(f"the store name is empty; give one such as {example}", field=FIELD)
    path = Path(text)
    if not path.parent.is_dir():
        raise InputError(f"folder {path.parent} of {text} does not exist", field=FIELD)
    for role, other in inputs.items():
        if path.exists() and Path(other).exists() and path.resolve() == Path(other).resolve():
            raise InputError(f"{text} is the {role}; choose another name", field=FIELD)
    if path.exists() and not path.is_dir():
        raise InputError(
            f"{text} exists and is not a Zarr store (a folder); choose another name", field=FIELD
        )
    if not os.access(path.parent, os.W_OK | os.X_OK):
        raise InputError(f"cannot write in folder {path.parent} (permission denied)", field=FIELD)
    return path
