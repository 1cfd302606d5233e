"""Can a scenario be the measured target? Checks before its geometry is used on a pass.

``period --scenario``, ``spin-axis`` and ``reflection-map`` take the geometry of the measured
epochs from a scenario (orbit, site, Sun, attitude). A scenario of another satellite, another
site or another night gives a geometry that has nothing to do with the measurements, and an
answer without meaning. What can be checked:

* **Seen at all**: light was measured at the epochs, so the target was above the horizon and,
  under the Sun, outside the Earth's shadow. The scenario must agree at most of them:
  refused where it puts the target below the horizon (elevation < 0, not the scenario's own
  ``min_elevation_deg``, a choice) or, for sunlight, in the umbra at more than
  :data:`MAX_UNSEEN_FRACTION` of them (a little slack for an old element set near the
  horizon or the shadow's edge).
* **Where the file saw it**: a speclight NetCDF records ``elevation`` and ``azimuth``; the
  scenario's direction must lie within :data:`MAX_DIRECTION_DEG` of it (median over the
  epochs).
* **Which satellite**: where both the file's own scenario (``scenario_yaml``) and the given
  one name a catalogue number (a TLE's, or ``norad_id``), they must be the same.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.estimate.inputs.cost_limits import time_span_text
from speclight.scenario import LoadedScenario

#: Largest fraction of the measured epochs at which the scenario may put the target below
#: the horizon or in the umbra (module docstring).
MAX_UNSEEN_FRACTION = 0.5
#: Largest median angle between the scenario's and the file's target direction [deg]: an
#: element set a few days old is off by tens of km along track, well under a degree from
#: the ground; another satellite or site is off by tens of degrees.
MAX_DIRECTION_DEG = 5.0
NETCDF_SUFFIXES = (".nc", ".nc4", ".netcdf", ".h5")


def catalogue_number(loaded: LoadedScenario) -> int | None:
    """The NORAD catalogue number of a scenario's orbit (TLE line 1, or ``norad_id``)."""
    orb = loaded.scenario.orbit
    if orb.norad_id is not None:
        return int(orb.norad_id)
    if orb.tle:
        for line in orb.tle.splitlines():
            text = line.strip()
            if text.startswith("1 ") and text[2:7].strip().isdigit():
                return int(text[2:7])
    return None


def _window_text(loaded: LoadedScenario) -> str:
    t = loaded.scenario.time
    return f"{t.start:%Y-%m-%dT%H:%M:%S} .. {t.stop:%Y-%m-%dT%H:%M:%S} UTC"


def _overlap_text(loaded: LoadedScenario, time_utc: NDArray[np.datetime64]) -> str:
    t = loaded.scenario.time
    start = np.datetime64(t.start.replace(tzinfo=None), "ns")
    stop = np.datetime64(t.stop.replace(tzinfo=None), "ns")
    inside = (time_utc >= start) & (time_utc <= stop)
    return " (no measured epoch lies in it)" if not inside.any() else ""


def check_scenario_sees(
    loaded: LoadedScenario,
    measured: str | Path,
    time_utc: NDArray[np.datetime64],
    light: str = "sun",
) -> None:
    """Refuse a scenario that cannot be the target measured at ``time_utc`` (module doc).

    Parameters
    ----------
    loaded
        The scenario whose geometry will be used.
    measured
        The measured file (a NetCDF's recorded direction and scenario are compared).
    time_utc
        (N,) the epochs with a usable measurement.
    light
        ``"sun"``: the target must be sunlit too; ``"laser"``: above the horizon only.
    """
    from speclight.simulation.geometry_stage import scenario_geometry

    time_utc = np.asarray(time_utc, dtype="datetime64[ns]")
    if time_utc.size == 0:
        return
    recorded = _recorded(Path(measured))
    if recorded is not None:
        _check_catalogue(loaded, recorded[2], str(measured))
    geo = scenario_geometry(loaded, time_utc)
    below = ~(geo.elevation_deg >= 0.0)
    dark = ~(geo.sunlit_fraction > 0.0) if light == "sun" else np.zeros(below.shape, bool)
    unseen = below | dark
    if unseen.mean() > MAX_UNSEEN_FRACTION:
        elev = geo.elevation_deg[np.isfinite(geo.elevation_deg)]
        span = f"{elev.min():.0f} to {elev.max():.0f} deg" if elev.size else "unknown"
        raise InputError(
            f"the scenario cannot be the measured target: at {int(below.sum())} of the "
            f"{time_utc.size} measured epochs it puts the target below the horizon "
            f"(elevation {span})"
            + (f" and at {int(dark.sum())} in the Earth's shadow" if light == "sun" else "")
            + f"; measured: {time_span_text(time_utc)}, the scenario's time window "
            f"{_window_text(loaded)}{_overlap_text(loaded, time_utc)}, site lat "
            f"{loaded.scenario.observer.latitude_deg:g} "
            f"lon {loaded.scenario.observer.longitude_deg:g} deg: give the scenario of this "
            "target, site and night",
            source=loaded.source,
            field="orbit",
        )
    if recorded is not None:
        t_file, direction = recorded[0], recorded[1]
        sep = _separation_deg(geo.azimuth_deg, geo.elevation_deg, t_file, direction, time_utc)
        if sep is not None and sep > MAX_DIRECTION_DEG:
            raise InputError(
                f"the scenario cannot be the measured target: its direction from the site is "
                f"{sep:.1f} deg from where {measured} saw the target (median over the epochs; "
                f"accepted: {MAX_DIRECTION_DEG:g} deg): another satellite, site or time",
                source=loaded.source,
                field="orbit",
            )


def _recorded(path: Path) -> tuple[NDArray[np.datetime64], NDArray, int | None] | None:
    """A NetCDF's (time, (azimuth, elevation) [deg], catalogue number or None), or None."""
    if path.suffix.lower() not in NETCDF_SUFFIXES:
        return None
    import xarray as xr

    from speclight.scenario import parse_scenario

    with xr.open_dataset(path, engine="h5netcdf") as ds:
        if "azimuth" not in ds or "elevation" not in ds:
            return None
        t = ds["time"].values.astype("datetime64[ns]")
        direction = np.stack([ds["azimuth"].values, ds["elevation"].values], axis=1)
        text = ds.attrs.get("scenario_yaml")
    number = None
    if text is not None:
        try:
            number = catalogue_number(parse_scenario(str(text), source=f"{path} (scenario_yaml)"))
        except InputError:  # a scenario the file carries but this version cannot read
            number = None
    return t, direction.astype(float), number


def _check_catalogue(loaded: LoadedScenario, recorded: int | None, src: str) -> None:
    given = catalogue_number(loaded)
    if recorded is not None and given is not None and recorded != given:
        raise InputError(
            f"the scenario's orbit is of catalogue number {given}, but {src} was made for "
            f"{recorded} (its scenario_yaml): give the scenario of the measured target",
            source=loaded.source,
            field="orbit",
        )


def _separation_deg(
    az_deg: NDArray,
    el_deg: NDArray,
    t_file: NDArray[np.datetime64],
    direction: NDArray,
    time_utc: NDArray[np.datetime64],
) -> float | None:
    """Median angle [deg] between the scenario's and the file's (az, el) at common epochs."""
    common, i_file, i_ours = np.intersect1d(t_file, time_utc, return_indices=True)
    if common.size == 0:
        return None
    a1, e1 = np.radians(direction[i_file, 0]), np.radians(direction[i_file, 1])
    a2, e2 = np.radians(az_deg[i_ours]), np.radians(el_deg[i_ours])
    c = np.sin(e1) * np.sin(e2) + np.cos(e1) * np.cos(e2) * np.cos(a1 - a2)
    sep = np.degrees(np.arccos(np.clip(c, -1.0, 1.0)))
    sep = sep[np.isfinite(sep)]
    return float(np.median(sep)) if sep.size else None


__all__ = [
    "MAX_DIRECTION_DEG",
    "MAX_UNSEEN_FRACTION",
    "catalogue_number",
    "check_scenario_sees",
]
