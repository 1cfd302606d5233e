"""Assemble the output :class:`xarray.Dataset` (SPEC section 4) from the stage results."""

from __future__ import annotations

from datetime import UTC, datetime
from typing import Any

import numpy as np
import xarray as xr

from speclight.constants import AU_M
from speclight.info import engine_versions
from speclight.scenario import LoadedScenario
from speclight.simulate import variables as v
from speclight.simulate.geometry_stage import Geometry


def geometry_dataset(geo: Geometry) -> xr.Dataset:
    """The geometry variables of SPEC section 4 on the ``time`` and ``xyz`` dimensions."""
    t = ("time",)
    txyz = ("time", "xyz")
    data: dict[str, tuple[tuple[str, ...], Any]] = {
        "range": (t, geo.range_m),
        "azimuth": (t, geo.azimuth_deg),
        "elevation": (t, geo.elevation_deg),
        "phase_angle": (t, geo.phase_angle_deg),
        "sunlit": (t, geo.sunlit_fraction),
        "sun_direction_body": (txyz, geo.sun_direction_body),
        "observer_direction_body": (txyz, geo.observer_direction_body),
        "phase_vector_body": (txyz, geo.phase_vector_body),
        "target_position_gcrs": (txyz, geo.r_target_gcrs_m),
        "sun_distance": (t, geo.sun_distance_m / AU_M),
    }
    ds = xr.Dataset(
        {name: (dims, np.asarray(values), v.attrs(name)) for name, (dims, values) in data.items()},
        coords={"time": ("time", geo.time_utc), "xyz": ("xyz", np.array(["x", "y", "z"]))},
    )
    ds["attitude_quaternion"] = (
        ("time", "wxyz"),
        geo.quaternion_body_to_gcrs,
        v.attrs("attitude_quaternion"),
    )
    ds.coords["wxyz"] = ("wxyz", np.array(["w", "x", "y", "z"]))
    masks = np.array(sorted(v.FLAG_MEANINGS), dtype=np.uint8)
    ds["flags"] = (
        t,
        geo.flags,
        {
            **v.attrs("flags"),
            "flag_masks": masks,
            "flag_meanings": " ".join(v.FLAG_MEANINGS[int(m)] for m in masks),
        },
    )
    ds["time"].attrs.update({"long_name": "epoch (UTC)", "standard_name": "time"})
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
