"""The simulation pipeline: geometry -> attitude -> (reflection -> atmosphere -> instrument).

Each stage is a subpackage with a plain-array core; :func:`simulate` calls them in order
and keeps every intermediate result in the output dataset.

``speclight.simulate`` is both this package and the API's function
(:func:`speclight.python_api.simulate`): importing a submodule makes Python set the package as the
attribute ``simulate`` of ``speclight``, over the function, so the package itself is
callable and calls the function.
"""

import sys
from types import ModuleType
from typing import Any

from speclight.simulate.pipeline import SimulationResult, simulate


class _CallablePackage(ModuleType):
    def __call__(self, *args: Any, **kwargs: Any) -> SimulationResult:
        """``speclight.simulate(scenario, overrides, progress=False)``: see
        :func:`speclight.python_api.simulate`."""
        from speclight.python_api import simulate as api_simulate

        return api_simulate(*args, **kwargs)


sys.modules[__name__].__class__ = _CallablePackage

__all__ = ["SimulationResult", "simulate"]
