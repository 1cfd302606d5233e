"""A small on-disk cache of arrays for expensive, deterministic results (6S runs, tables).

The folder is ``$SPECLIGHT_CACHE_DIR``, else ``~/.cache/speclight``. Entries are ``.npz``
files named by a hash of everything the result depends on, and each stores that key too, so
that a file written for another key (by another program, an older speclight, a copy) is
recognised. A cache that cannot be read or written is simply bypassed:

- an entry that cannot be used (truncated by an interrupted run, corrupt, foreign) is
  ignored, recomputed and replaced, with one warning per entry and run naming it;
- an entry is written to a temporary file that is then renamed over it, so readers and
  concurrent writers of the same entry only ever see a whole file;
- temporary files left by interrupted writes are removed by the next write in their
  folder once their writer is gone (same host) or they are older than :data:`STALE_TEMP_S`.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import re
import socket
import stat
import tempfile
import time
import warnings
import zipfile
import zlib
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

#: Age [s] after which a temporary file of an unfinished write is removed whoever wrote it
#: (a write takes well under a second; an hour leaves room for slow shared file systems).
STALE_TEMP_S = 3600.0
#: Name of the array holding the entry's key (JSON) inside each entry.
KEY_ARRAY = "__speclight_cache_key__"
_TEMP = re.compile(r"^\.[0-9a-f]+\.(?:(?P<host>.+)-(?P<pid>\d+)\.)?[^.]+\.(?:tmp|npz)$")
#: Entries already reported as unusable in this process (one warning each per run).
_reported: set[Path] = set()


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
    versions), as JSON-serialisable values; ``root`` overrides the cache folder. An entry
    that cannot be used is reported with a :class:`UserWarning`, recomputed and replaced.
    """
    key_json = json.dumps(key, sort_keys=True, default=str)
    digest = hashlib.sha256(key_json.encode()).hexdigest()
    path = cache_root(root) / kind / f"{digest[:32]}.npz"
    arrays, problem = _read_entry(path, key_json)
    if arrays is not None:
        return arrays
    if problem is not None and path not in _reported:
        _reported.add(path)
        warnings.warn(
            f"cache entry {path} {problem}; it is ignored, recomputed and replaced",
            UserWarning,
            stacklevel=2,
        )
    arrays = compute()
    with contextlib.suppress(OSError):  # a read-only or full cache folder only costs time
        _write_entry(path, arrays, key_json)
    return arrays


def _read_entry(path: Path, key_json: str) -> tuple[dict[str, NDArray[Any]] | None, str | None]:
    """The arrays of an entry, or None and why it cannot be used (None: there is none)."""
    unreadable = (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile, zlib.error)
    try:
        if not stat.S_ISREG(os.stat(path).st_mode):
            return None, "is not a regular file"
        with open(path, "rb") as f:  # opened here, so that a failing np.load leaks no handle
            loaded = np.load(f, allow_pickle=False)
            if not isinstance(loaded, np.lib.npyio.NpzFile):
                return None, "is not an .npz archive"
            with loaded as data:
                arrays = {name: data[name] for name in data.files}
    except FileNotFoundError:
        return None, None
    except unreadable as exc:
        return None, f"cannot be read: it is truncated or corrupt ({type(exc).__name__})"
    stored = arrays.pop(KEY_ARRAY, None)
    if stored is None or stored.shape != () or str(stored) != key_json:
        return None, "was not written for this key (a foreign file or an older speclight)"
    return arrays, None


def _write_entry(path: Path, arrays: Mapping[str, NDArray[Any]], key_json: str) -> None:
    """Write an entry atomically; remove the temporary file if the write is interrupted."""
    path.parent.mkdir(parents=True, exist_ok=True)
    remove_stale_temps(path.parent)
    host = re.sub(r"[^A-Za-z0-9_.-]", "_", socket.gethostname())
    fd, tmp = tempfile.mkstemp(
        prefix=f".{path.stem}.{host}-{os.getpid()}.", suffix=".tmp", dir=path.parent
    )
    try:
        with os.fdopen(fd, "wb") as f:
            np.savez(f, **arrays, **{KEY_ARRAY: np.array(key_json)})  # type: ignore[arg-type]
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:  # also KeyboardInterrupt: leave no temporary file behind
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def remove_stale_temps(folder: Path, now_s: float | None = None) -> list[Path]:
    """Remove the temporary files of unfinished writes in ``folder``; return those removed.

    A temporary file is removed when it is older than :data:`STALE_TEMP_S`, or when it was
    written on this host by a process that no longer exists. Others may belong to a write
    in progress and are kept.
    """
    now = time.time() if now_s is None else now_s
    host = re.sub(r"[^A-Za-z0-9_.-]", "_", socket.gethostname())
    removed = []
    for candidate in folder.glob(".*"):
        match = _TEMP.match(candidate.name)
        if match is None:
            continue
        try:
            age_s = now - candidate.stat().st_mtime
        except OSError:
            continue
        dead = match["host"] == host and not _process_alive(int(match["pid"]))
        if age_s > STALE_TEMP_S or dead:
            with contextlib.suppress(OSError):
                candidate.unlink()
                removed.append(candidate)
    return removed


def _process_alive(pid: int) -> bool:
    """True if a process of this id exists (always True where that cannot be asked)."""
    if os.name != "posix":  # os.kill(pid, 0) would not be a harmless probe on Windows
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # e.g. PermissionError: it exists, under another user
        return True
    return True
