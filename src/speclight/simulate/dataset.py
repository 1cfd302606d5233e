"""Assemble the output :class:`xarray.Dataset` (docs/output.md) from the stage results."""

from __future__ import annotations

from datetime import UTC, datetime
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from speclight import schema
from speclight.constants import AU_M
from speclight.info import engine_versions
from speclight.scenario import LoadedScenario
from speclight.simulate.geometry_stage import Geometry


def geometry_dataset(geo: Geometry, flags: NDArray[np.uint8] | None = None) -> xr.Dataset:
    """The geometry variables on the ``time`` and ``xyz`` dimensions.

    ``flags``: the run's flag bits (geometry and later stages), default ``geo.flags``.
    """
    data: dict[str, Any] = {
        "range": geo.range_m,
        "azimuth": geo.azimuth_deg,
        "elevation": geo.elevation_deg,
        "phase_angle": geo.phase_angle_deg,
        "sunlit": geo.sunlit_fraction,
        "sun_direction_body": geo.sun_direction_body,
        "observer_direction_body": geo.observer_direction_body,
        "phase_vector_body": geo.phase_vector_body,
        "target_position_gcrs": geo.r_target_gcrs_m,
        "sun_distance": geo.sun_distance_m / AU_M,
    }
    ds = xr.Dataset(
        {name: schema.variable(name, np.asarray(values)) for name, values in data.items()},
        coords={"time": ("time", geo.time_utc), "xyz": ("xyz", np.array(["x", "y", "z"]))},
    )
    ds["attitude_quaternion"] = schema.variable("attitude_quaternion", geo.quaternion_body_to_gcrs)
    ds.coords["wxyz"] = ("wxyz", np.array(["w", "x", "y", "z"]))
    masks = np.array(sorted(schema.FLAG_MEANINGS), dtype=np.uint8)
    ds["flags"] = schema.variable(
        "flags",
        geo.flags if flags is None else flags,
        flag_masks=masks,
        flag_meanings=" ".join(schema.FLAG_MEANINGS[int(m)] for m in masks),
    )
    ds["time"].attrs.update(schema.COORDINATES["time"])
    return ds


def global_attributes(
    loaded: LoadedScenario, extra: dict[str, Any] | None = None
) -> dict[str, Any]:
    """Global attributes: CF conventions, the scenario YAML, versions, variant, seed."""
    from speclight import __version__

    sc = loaded.scenario
    attrs: dict[str, Any] = {
        "Conventions": "CF-1.10",
        "title": f"speclight simulation '{sc.name}'",
        "source": f"speclight {__version__}",
        "history": f"{datetime.now(UTC).isoformat(timespec='seconds')} speclight simulate",
        "scenario_name": sc.name,
        "scenario_yaml": loaded.yaml_text,
        "scenario_source": loaded.source,
        "speclight_version": __version__,
        "seed": sc.render.seed,
        "observer_latitude_deg": sc.observer.latitude_deg,
        "observer_longitude_deg": sc.observer.longitude_deg,
        "observer_altitude_m": sc.observer.altitude_m,
        "min_elevation_deg": sc.observer.min_elevation_deg,
    }
    for name, version in engine_versions().items():
        attrs[f"version_{name}"] = version
    attrs.update(extra or {})
    return attrs
