"""The simulation pipeline: geometry -> attitude -> (reflection -> atmosphere -> instrument).

Each stage is a subpackage with a plain-array core; :func:`simulate` calls them in order
and keeps every intermediate result in the output dataset.
"""

from speclight.simulate.pipeline import SimulationResult, simulate

__all__ = ["SimulationResult", "simulate"]
