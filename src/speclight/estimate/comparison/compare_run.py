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

from speclight import orbit, schema
from speclight.constants import C_M_S
from speclight.errors import InputError
from speclight.estimate.comparison.compare_stats import residual_statistics
from speclight.estimate.inputs.measured_checks import no_usable_epochs
from speclight.estimate.inputs.observations import FIELD, Observations
from speclight.orbit.observed_position import (
    observed_trajectory,
    place_target_gcrs_m,
    range_from_height_m,
)
from speclight.orbit.timescale import time_from_utc
from speclight.scenario import LoadedScenario
from speclight.scenario.overrides import with_overrides

F64 = NDArray[np.float64]
#: Least time of one site's simulation [s]: the target's build and one render launch, a lower
#: bound of the 5.7 s per site of 100 observations each measured in BENCHMARKS.md ("Compare").
SECONDS_PER_SITE = 1.0
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


def _placed(loaded: LoadedScenario, obs: Observations) -> Any:
    """The trajectory through the observed positions of every row (all sites)."""
    if not obs.has_positions:
        bad = ~(
            np.isfinite(obs.elevation_deg) & (np.isfinite(obs.range_m) | np.isfinite(obs.height_m))
        )
        line = int(obs.line[np.flatnonzero(bad)[0]])
        raise InputError(
            f"line {line}: the scenario has orbit: {{observed: true}}, so every row must give "
            "where the target was seen: elevation_deg, azimuth_deg and range_m (or height_m)",
            source=obs.source,
            field=FIELD,
        )
    n = obs.time_utc.size
    r = np.full((n, 3), np.nan)
    rng = obs.range_m.copy()
    for (lat, lon, alt), idx in obs.site_groups():
        site = orbit.Site(lat, lon, alt)
        need = idx[~np.isfinite(rng[idx])]
        if need.size:
            rng[need] = range_from_height_m(
                site, obs.azimuth_deg[need], obs.elevation_deg[need], obs.height_m[need]
            )
        t = time_from_utc(obs.time_utc[idx])
        r[idx] = place_target_gcrs_m(
            site, t, obs.azimuth_deg[idx], obs.elevation_deg[idx], rng[idx]
        )
    emitted = obs.time_utc.copy()
    if loaded.scenario.observer.light_time:
        delay_ns = np.rint(np.nan_to_num(rng) / C_M_S * 1e9).astype("timedelta64[ns]")
        emitted = obs.time_utc - delay_ns
    return observed_trajectory(emitted, r)


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
    trajectory = _placed(loaded, obs) if sc.orbit.observed else None
    notes: list[str] = []
    if trajectory is None and np.any(np.isfinite(obs.elevation_deg)):
        notes.append(
            "the rows' elevation/azimuth/range are not used: the scenario has an orbit "
            "(orbit: {observed: true} places the target there instead)"
        )
    n = obs.time_utc.size
    sim = np.full(n, np.nan)
    flags = np.zeros(n, dtype=schema.FLAG_DTYPE)
    geo: dict[str, F64] = {k: np.full(n, np.nan) for k in GEOMETRY}
    for name in ("sun_direction_body", "observer_direction_body"):
        geo[name] = np.full((n, 3), np.nan)
    groups = obs.site_groups()
    _check_sites(len(groups), obs)
    for (lat, lon, alt), idx in groups:
        site_scenario = with_overrides(
            base,
            {
                "observer.latitude_deg": lat,
                "observer.longitude_deg": lon,
                "observer.altitude_m": alt,
            },
        )
        epochs = np.unique(obs.time_utc[idx])
        if trajectory is not None:
            g = scenario_geometry(site_scenario, epochs, trajectory=trajectory)
            ds = simulate(site_scenario, progress, geometry=g).dataset
        else:
            ds = simulate(site_scenario, progress, time_utc=epochs).dataset
        k = np.searchsorted(epochs, obs.time_utc[idx])
        band_index = {str(b): col for col, b in enumerate(ds["band"].values)}
        cols = np.array([band_index[obs.band[i]] for i in idx], dtype=np.intp)
        sim[idx] = ds["ab_magnitude"].values[k, cols]
        flags[idx] = ds["flags"].values[k]
        for name, var in GEOMETRY.items():
            geo[name][idx] = ds[var].values[k]
    if not np.any(np.isfinite(sim) & np.isfinite(obs.magnitude)):
        raise no_usable_epochs(n, loaded.source, obs.source, FIELD, "observed")
    return CompareResult(dataset=_dataset(loaded, obs, sim, flags, geo), notes=notes)


def _check_sites(n_sites: int, obs: Observations) -> None:
    """Refuse observations from so many sites that one simulation each cannot finish in a
    day (:mod:`speclight.estimate.inputs.cost_limits`), at :data:`SECONDS_PER_SITE` each at
    least."""
    from speclight.estimate.inputs.cost_limits import check_cost

    check_cost(
        FIELD, f"{obs.source} ({obs.time_utc.size} rows)",
        f"one simulation for each of its {n_sites} sites (at least {SECONDS_PER_SITE:g} s "
        "each: the target's build and a render launch)",
        0.0, n_sites * SECONDS_PER_SITE,
        "group the observations by site into fewer files, or round the sites' coordinates",
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
    ds.attrs.update(residual_statistics(residual, geo["phase_angle"], geo["elevation"]))
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


def _flag_attrs() -> dict[str, Any]:
    return schema.flag_attributes()
