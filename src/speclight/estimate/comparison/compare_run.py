"""``speclight compare``: a scenario simulated at every observed epoch and site, against the
observed magnitudes (docs/compare.md).

The observations are grouped by site; each site is one simulation of all its epochs (the
scenario with its observer moved to the site, :func:`~speclight.scenario.overrides.
with_overrides`). A row's band is a band of the scenario or a speclite filter, which is
then added to the scenario's bands (its AB magnitude: band response only). Where the
scenario has ``orbit: {observed: true}``, the target is placed where each row saw it
(:mod:`speclight.orbit.observed_position`). Epochs where the target is not observable
(below the minimum elevation, in the Earth's shadow, no attitude) keep their row with a
NaN simulated magnitude and their ``flags``; where no row is observable the comparison is
refused (an :class:`~speclight.errors.InputError`: the times or the scenario are wrong).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from speclight import schema
from speclight.errors import InputError
from speclight.estimate.comparison.compare_geometry import (
    RowGroup,
    join_geometries,
    row_groups,
    single_epoch_objects,
)
from speclight.estimate.comparison.compare_stats import per_object, residual_statistics
from speclight.estimate.inputs.measured_checks import no_usable_epochs
from speclight.estimate.inputs.observations import FIELD, Observations
from speclight.scenario import LoadedScenario
from speclight.scenario.overrides import with_overrides

F64 = NDArray[np.float64]
#: Least time of one site's simulation [s]: the target's build and one render launch, a lower
#: bound of the 5.7 s per site of 100 observations each measured in BENCHMARKS.md ("Compare").
SECONDS_PER_SITE = 1.0
#: Least time of one geometry pass of a group of objects (``orbit: {observed: true}`` with an
#: ``object`` column) [s]: a lower bound of the 0.0034-0.037 s measured per pass of 3 epochs
#: on 2 shared cores (``bench/bench_compare_objects.py``, BENCHMARKS.md, "Compare").
SECONDS_PER_GROUP = 0.003
#: Per-observation geometry copied from the simulation: output name -> simulate variable.
GEOMETRY = {
    "phase_angle": "phase_angle",
    "range": "range",
    "elevation": "elevation",
    "azimuth": "azimuth",
    "sunlit": "sunlit",
    "sun_direction_body": "sun_direction_body",
    "observer_direction_body": "observer_direction_body",
}


@dataclass
class CompareResult:
    """The comparison dataset (CMP.nc) and what to tell the user."""

    dataset: xr.Dataset
    notes: list[str] = field(default_factory=list)


def _bands(loaded: LoadedScenario, obs: Observations) -> list[dict[str, Any]]:
    """The scenario's bands plus one speclite filter band per other band name of ``obs``."""
    from speclight.instrument.bands import filter_band

    sc = loaded.scenario
    bands = [b.model_dump(mode="json", exclude_none=True) for b in sc.instrument.bands]
    known = {b.name for b in sc.instrument.bands}
    for name in dict.fromkeys(obs.band):
        if name in known:
            continue
        line = int(obs.line[obs.band.index(name)])
        try:
            filter_band(name)
        except InputError as exc:
            raise InputError(
                f"line {line}, column 'band': '{name}' is neither a band of the scenario "
                f"({', '.join(sorted(known)) or 'none'}) nor a speclite filter ({exc.message})",
                source=obs.source,
                field=FIELD,
            ) from None
        bands.append({"name": name, "filter": name})
        known.add(name)
    return bands


def compare(loaded: LoadedScenario, obs: Observations, progress: bool = False) -> CompareResult:
    """Simulate ``loaded`` at every epoch and site of ``obs`` and compare the magnitudes.

    Parameters
    ----------
    loaded
        The scenario: target, attitude, atmosphere, instrument, orbit (or
        ``orbit: {observed: true}``); its observer's site is replaced by each row's.
    obs
        From :func:`~speclight.estimate.inputs.observations.read_observations`.
    progress
        Progress bars on a terminal.

    Returns
    -------
    CompareResult
        ``dataset`` with dimension ``obs`` (one per row, file order): see docs/compare.md.
    """
    from speclight.simulation.geometry_stage import scenario_geometry
    from speclight.simulation.pipeline import simulate

    sc = loaded.scenario
    if sc.target is None and sc.render.mode != "map":
        raise InputError(
            "the scenario has no target: compare needs simulated magnitudes (add a target)",
            source=loaded.source,
            field="target",
        )
    bands = _bands(loaded, obs)
    base = loaded
    if len(bands) > len(sc.instrument.bands):  # speclite filters added
        base = with_overrides(loaded, {"instrument.bands": bands})  # a missing section is made
    groups = row_groups(loaded, obs)
    notes: list[str] = []
    if not sc.orbit.observed and np.any(np.isfinite(obs.elevation_deg)):
        notes.append(
            "the rows' elevation/azimuth/range are not used: the scenario has an orbit "
            "(orbit: {observed: true} places the target there instead)"
        )
    n_objects = len(obs.object_index()[0])
    if not sc.orbit.observed and obs.object_name is not None and n_objects > 1:
        notes.append(
            f"the scenario's orbit is used for all {n_objects} objects: the object column "
            "only groups the statistics (orbit: {observed: true} gives each object the "
            "trajectory of its own rows)"
        )
    lonely = single_epoch_objects(loaded, obs)
    if lonely:
        notes.append(_lonely_note(lonely))
    n = obs.time_utc.size
    sim = np.full(n, np.nan)
    flags = np.full(n, schema.FLAG_ORBIT_FAILED, dtype=schema.FLAG_DTYPE)  # until simulated
    geo: dict[str, F64] = {k: np.full(n, np.nan) for k in GEOMETRY}
    for name in ("sun_direction_body", "observer_direction_body"):
        geo[name] = np.full((n, 3), np.nan)
    sites = [(key, _site_parts(obs, rows, groups)) for key, rows in obs.site_groups()]
    _check_sites(len(sites), sum(len(parts) for _, parts in sites), obs)
    for (lat, lon, alt), parts in sites:
        if not parts:  # every row's object without a placed position
            continue
        site_scenario = with_overrides(
            base,
            {
                "observer.latitude_deg": lat,
                "observer.longitude_deg": lon,
                "observer.altitude_m": alt,
            },
        )
        if parts[0][2] is None:  # the scenario's orbit: one group
            ds = simulate(site_scenario, progress, time_utc=parts[0][1]).dataset
        else:
            g = join_geometries(
                [scenario_geometry(site_scenario, epochs, trajectory=tr) for _, epochs, tr in parts]
            )
            ds = simulate(site_scenario, progress, geometry=g).dataset
        band_index = {str(b): col for col, b in enumerate(ds["band"].values)}
        offset = 0
        for idx, epochs, _ in parts:
            k = offset + np.searchsorted(epochs, obs.time_utc[idx])
            offset += epochs.size
            cols = np.array([band_index[obs.band[i]] for i in idx], dtype=np.intp)
            sim[idx] = ds["ab_magnitude"].values[k, cols]
            flags[idx] = ds["flags"].values[k]
            for name, var in GEOMETRY.items():
                geo[name][idx] = ds[var].values[k]
    if not np.any(np.isfinite(sim) & np.isfinite(obs.magnitude)):
        err = no_usable_epochs(n, loaded.source, obs.source, FIELD, "observed")
        if lonely:  # the likelier cause
            raise InputError(
                f"{err.message}; {_lonely_note(lonely)}", source=obs.source, field=FIELD
            ) from None
        raise err
    return CompareResult(dataset=_dataset(loaded, obs, sim, flags, geo), notes=notes)


def _lonely_note(names: list[str]) -> str:
    shown = ", ".join(f"'{o}'" for o in names[:5]) + (", ..." if len(names) > 5 else "")
    return (
        f"{len(names)} object(s) seen at one epoch only ({shown}): one position gives no "
        "velocity, so an attitude that needs it (nadir; a velocity or orbit_normal "
        "constraint) is undefined there (flag attitude_undefined, left out of the "
        "statistics); give each object at least two rows at most 30 s apart"
    )


def _site_parts(
    obs: Observations, site_rows: NDArray[np.intp], groups: list[RowGroup]
) -> list[tuple[NDArray[np.intp], NDArray[np.datetime64], Any]]:
    """Per group with rows at this site: those rows (ascending), their distinct epochs
    (sorted) and the group's trajectory (None: the scenario's orbit)."""
    parts = []
    for group in groups:
        idx = np.intersect1d(site_rows, group.rows)
        if idx.size:
            parts.append((idx, np.unique(obs.time_utc[idx]), group.trajectory))
    return parts


def _check_sites(n_sites: int, n_passes: int, obs: Observations) -> None:
    """Refuse observations from so many sites (or objects seen at once) that one simulation
    each (and one geometry pass per group of objects at each site) cannot finish in a day
    (:mod:`speclight.estimate.inputs.cost_limits`), at :data:`SECONDS_PER_SITE` and
    :data:`SECONDS_PER_GROUP` each at least."""
    from speclight.estimate.inputs.cost_limits import check_cost

    what = (
        f"one simulation for each of its {n_sites} sites (at least {SECONDS_PER_SITE:g} s "
        "each: the target's build and a render launch)"
    )
    if n_passes > n_sites:
        what += (
            f" and {n_passes} geometry passes, one per site and group of objects seen at "
            f"overlapping times (at least {SECONDS_PER_GROUP:g} s each)"
        )
    check_cost(
        FIELD, f"{obs.source} ({obs.time_utc.size} rows)", what,
        0.0, n_sites * SECONDS_PER_SITE + n_passes * SECONDS_PER_GROUP,
        "split the file, group the observations by site, or round the sites' coordinates",
    )  # fmt: skip


def _dataset(
    loaded: LoadedScenario,
    obs: Observations,
    sim: F64,
    flags: NDArray[np.uint16],
    geo: dict[str, F64],
) -> xr.Dataset:
    from speclight import schema

    residual = obs.magnitude - sim
    columns: list[tuple[str, Any, str, str]] = [
        ("time", obs.time_utc, "", "observation epoch (UTC)"),
        ("magnitude_observed", obs.magnitude, "mag", "observed AB magnitude"),
        ("magnitude_simulated", sim, "mag", "simulated AB magnitude (NaN: not observable)"),
        ("residual", residual, "mag", "observed minus simulated magnitude"),
        ("magnitude_sigma", obs.magnitude_sigma, "mag", "standard deviation of the observed"),
        ("band", np.array(obs.band, dtype=object), "", "band or speclite filter"),
        ("site_latitude", obs.latitude_deg, "degree_north", "site geodetic latitude (WGS84)"),
        ("site_longitude", obs.longitude_deg, "degree_east", "site longitude"),
        ("site_altitude", obs.altitude_m, "m", "site height above the WGS84 ellipsoid"),
        ("line", obs.line, "", "line of the observation in the OBSERVATIONS file"),
    ]
    ds = xr.Dataset()
    for name, data, unit, long_name in columns:
        attrs = {"units": unit, "long_name": long_name} if unit else {"long_name": long_name}
        ds[name] = ("obs", data, attrs)
    for name in GEOMETRY:
        dims = ("obs", "xyz") if geo[name].ndim == 2 else ("obs",)
        ds[name] = (dims, geo[name], schema.attrs(name))
    ds["flags"] = ("obs", flags, {**schema.attrs("flags"), **_flag_attrs()})
    ds.attrs.update(residual_statistics(obs.magnitude, sim, geo["phase_angle"], geo["elevation"]))
    if obs.object_name is not None:
        ds = _add_objects(ds, obs, sim)
    ds.attrs.update(
        {
            "title": "speclight compare: simulated against observed magnitudes",
            "Conventions": "CF-1.10",
            "observations_file": obs.source,
            "scenario_yaml": loaded.yaml_text,
            "n_sites": len(obs.site_groups()),
        }
    )
    return ds


#: Per-object variables of CMP.nc (described in :data:`speclight.schema.COMPARE_VARIABLES`)
#: -> key of :func:`~speclight.estimate.comparison.compare_stats.per_object`.
PER_OBJECT = {
    "n_per_object": "n",
    "residual_mean_per_object": "mean",
    "residual_rms_per_object": "rms",
    "residual_median_abs_per_object": "median_abs",
    "pearson_r_per_object": "pearson_r",
    "chi_square_per_object": "chi_square",
}


def _add_objects(ds: xr.Dataset, obs: Observations, sim: F64) -> xr.Dataset:
    """The ``object_id(obs)`` of each row and the statistics per object (dimension
    ``object``, first-seen order)."""
    table = schema.COMPARE_VARIABLES
    names, index = obs.object_index()
    stats = per_object(obs.magnitude, sim, index, len(names))
    ds["object_id"] = (
        "obs",
        np.array(obs.object_name, dtype=object),
        schema.attrs("object_id", table),
    )
    ds = ds.assign_coords(object=("object", np.array(names, dtype=object)))
    ds["object"].attrs.update(schema.COMPARE_COORDINATES["object"])
    for name, key in PER_OBJECT.items():
        data = stats[key].astype(np.int64) if key == "n" else stats[key]
        ds[name] = (table[name].dims, data, schema.attrs(name, table))
    ds.attrs["n_objects"] = len(names)
    return ds


def _flag_attrs() -> dict[str, Any]:
    return schema.flag_attributes()
