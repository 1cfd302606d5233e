"""Keep xarray from importing ``dask.array`` before a dask array can exist.

For every variable it builds, xarray asks whether the data is a dask array
(``xarray.namedarray.pycompat.array_type("dask")``), and the first time it asks it imports
``dask.array`` whenever dask is installed: about 0.08 s of CPU within a simulation's
start-up (0.15-0.35 s alone), in runs that never make a dask array (BENCHMARKS.md). A dask
array can exist only once ``dask.array`` has been imported (its class lives there), so until
then the answer is "no" without importing anything. :func:`defer_dask_array_import` puts
into xarray's cache of duck-array modules an entry for dask that answers from
``sys.modules``: no dask array type while ``dask.array`` is not imported,
``dask.array.Array`` as soon as it is (by the reflectivity maps' writer, a Dask cluster, the
user). xarray's answers are therefore the same as without the entry at every moment, and
nothing is kept from being imported: a broken dask install fails where dask is used, as
before.

The cache is xarray's own (``_cached_duck_array_modules``, since xarray 2023.x); where it is
missing or shaped otherwise (another xarray version) nothing is changed and xarray imports
``dask.array`` as it always did (slower, not wrong). tests/io/test_deferred_dask.py checks
that the entry is in place with the installed xarray and that dask arrays stay dask arrays.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
from typing import Any


class _DaskWhenImported:
    """xarray's record of dask (array types, module, version), read when asked."""

    available = True

    @property
    def type(self) -> tuple[type, ...]:
        """``(dask.array.Array,)`` once ``dask.array`` is imported, else ``()``."""
        array = getattr(sys.modules.get("dask.array"), "Array", None)
        return (array,) if isinstance(array, type) else ()

    @property
    def module(self) -> Any:
        return importlib.import_module("dask")

    @property
    def version(self) -> Any:
        from packaging.version import Version  # xarray's own dependency

        return Version(self.module.__version__)


def defer_dask_array_import() -> bool:
    """Let xarray import ``dask.array`` only when a dask array can exist (module docstring).

    Call before the process builds its first xarray variable; calling again is harmless.

    Returns
    -------
    bool
        True where the deferred entry is in place (dask installed, xarray's cache as
        expected and not yet holding dask's record); False where xarray is left as it is.
    """
    try:
        from xarray.namedarray import pycompat
    except ImportError:
        return False
    cache = getattr(pycompat, "_cached_duck_array_modules", None)
    if not isinstance(cache, dict):
        return False
    if "dask" in cache:  # asked already (dask.array imported then, or dask missing)
        return isinstance(cache["dask"], _DaskWhenImported)
    if importlib.util.find_spec("dask") is None:  # xarray's own answer costs nothing then
        return False
    cache["dask"] = _DaskWhenImported()
    return True
