"""The ``simulate`` pipeline."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from speclight.scenario import LoadedScenario
from speclight.simulate import variables as v
from speclight.simulate.dataset import geometry_dataset, global_attributes
from speclight.simulate.geometry import Geometry, compute_geometry


@dataclass
class SimulationResult:
    """The output dataset and the notes a user should read about the run."""

    dataset: xr.Dataset
    geometry: Geometry
    notes: list[str] = field(default_factory=list)


def _visibility_notes(geo: Geometry) -> list[str]:
    n = geo.flags.size
    observable = geo.observable
    lit = observable & (geo.sunlit_fraction > 0)
    notes = [
        f"{n} epochs: {int(observable.sum())} above the minimum elevation, "
        f"{int(lit.sum())} of them sunlit"
    ]
    if not np.any(~geo.orbit_ok) and not np.any(lit):
        notes.append(
            "the target is never both sunlit and above the minimum elevation in this time "
            "window: its brightness is zero or not observable at every epoch"
        )
    failed = int(np.count_nonzero(geo.flags & v.FLAG_ORBIT_FAILED))
    if failed:
        notes.append(f"{failed} epochs have no target position (flag orbit_failed)")
    return notes


def simulate(loaded: LoadedScenario, progress: bool = False) -> SimulationResult:
    """Run one scenario through the pipeline.

    Parameters
    ----------
    loaded
        A validated scenario (see :func:`speclight.scenario.load_scenario`).
    progress
        Show progress bars (for terminals).

    Returns
    -------
    SimulationResult
        The dataset of SPEC section 4 and notes for the user.
    """
    geo = compute_geometry(loaded)
    ds = geometry_dataset(geo)
    ds.attrs.update(global_attributes(loaded))
    return SimulationResult(dataset=ds, geometry=geo, notes=_visibility_notes(geo))
