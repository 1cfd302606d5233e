"""speclight: spectral light curves of satellites and space debris.

Simulates what a ground telescope measures from an orbiting target, wavelength by
wavelength, and inverts such measurements. The command line: ``speclight --help``. The
Python API (``docs/api.md``)::

    import speclight

    scenario = speclight.load("calsphere")  # a file, an example name, YAML text or a dict
    scenario = speclight.with_overrides(scenario, {"render.resolution_px": 64})
    result = speclight.simulate(scenario)
    result.dataset["ab_magnitude"]

The inversions are in :mod:`speclight.estimate`.
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version
from typing import TYPE_CHECKING, Any

try:
    __version__ = version("speclight")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0.0.0+unknown"

if TYPE_CHECKING:
    from speclight.errors import InputError
    from speclight.python_api import examples, load, simulate, with_overrides
    from speclight.scenario import LoadedScenario

_LAZY = {
    "load": "speclight.python_api",
    "simulate": "speclight.python_api",
    "with_overrides": "speclight.python_api",
    "examples": "speclight.python_api",
    "LoadedScenario": "speclight.scenario",
    "InputError": "speclight.errors",
}

__all__ = [
    "InputError",
    "LoadedScenario",
    "__version__",
    "examples",
    "load",
    "simulate",
    "with_overrides",
]


def __getattr__(name: str) -> Any:
    """The API's names, imported when first used (``import speclight`` stays light)."""
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'speclight' has no attribute '{name}'")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
