"""A small on-disk cache of arrays for expensive, deterministic results (6S runs, tables).

The folder is ``$SPECLIGHT_CACHE_DIR``, else ``~/.cache/speclight``. Entries are ``.npz``
files named by a hash of everything the result depends on; they are written atomically and
a cache that cannot be read or written is simply bypassed.
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray


def cache_root(override: Path | None = None) -> Path:
    """Cache folder: ``override``, else ``$SPECLIGHT_CACHE_DIR``, else ``~/.cache/speclight``."""
    if override is not None:
        return Path(override)
    env = os.environ.get("SPECLIGHT_CACHE_DIR")
    return Path(env).expanduser() if env else Path.home() / ".cache" / "speclight"


def cached_arrays(
    kind: str,
    key: Mapping[str, Any],
    compute: Callable[[], dict[str, NDArray[Any]]],
    root: Path | None = None,
) -> dict[str, NDArray[Any]]:
    """Return ``compute()``, from ``<cache>/<kind>/<hash of key>.npz`` when it is there.

    ``key`` must hold everything the result depends on (inputs, algorithm constants,
    versions), as JSON-serialisable values; ``root`` overrides the cache folder.
    """
    digest = hashlib.sha256(json.dumps(key, sort_keys=True, default=str).encode()).hexdigest()
    path = cache_root(root) / kind / f"{digest[:32]}.npz"
    try:
        with np.load(path) as data:
            return {name: data[name] for name in data.files}
    except (OSError, ValueError, EOFError):
        pass
    arrays = compute()
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=".npz", dir=path.parent)
        with os.fdopen(fd, "wb") as f:
            np.savez(f, **arrays)  # type: ignore[arg-type]
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except OSError:
        pass  # a read-only or full cache folder only costs time
    return arrays
