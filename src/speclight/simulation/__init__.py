"""The simulation pipeline: geometry -> attitude -> (reflection -> atmosphere -> instrument).

Each stage is a subpackage with a plain-array core; :func:`simulate` calls them in order
and keeps every intermediate result in the output dataset. The Python API's
``speclight.simulate(scenario, overrides)`` (:func:`speclight.python_api.simulate`) loads and
overrides a scenario, then calls it.
"""

from speclight.simulation.pipeline import SimulationResult, simulate

__all__ = ["SimulationResult", "simulate"]
