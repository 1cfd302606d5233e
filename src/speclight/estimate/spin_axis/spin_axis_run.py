"""What ``speclight spin-axis`` reads (scenario, measured pass, map) and writes (AXIS.nc).

The scenario gives the orbit, the observer and the spin model: its body axis
(``attitude.spin_body_axis``) and its period (``--period-s`` overrides; one of the two is
needed), and its own axis, which is marked as the "scenario axis" (the truth of a simulated
pass). The measured light curves are band reflectance factors
(:func:`speclight.estimate.inputs.reflectance_factors.read_reflectance_factors`: a simulate
NetCDF's, or a CSV's count rates turned into factors with the scenario's geometry; for a CSV
the scenario is run with ``render: {mode: map}`` on the given map, so nothing is rendered).
Under the Sun (``source="sun"``) the map's band count rates are compared; under coaxial lasers
(``"laser"``, the laser reflectance factors) the band rates of its phase-0 slice under the
lasers' lines (:mod:`.spin_axis_ranging`). Where the NetCDF has ``range_offset(time, band)``
and the map ``range_offset``, the ranging term is added (``ranging_weight``; None: balanced
over the grid where both have them, else 0).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.attitude.quaternion import quat_rotate
from speclight.errors import InputError
from speclight.estimate.spin_axis.spin_axis_core import (
    DEFAULT_AXIS_CHUNK,
    SpinAxisResult,
    check_search_options,
    spin_axis_search,
)
from speclight.estimate.spin_axis.spin_axis_lookup import (
    EpochGeometry,
    load_band_map,
    spin_frame_map,
)
from speclight.estimate.spin_axis.spin_axis_ranging import (
    check_ranging_weight,
    map_has_offsets,
    measured_offsets,
)
from speclight.scenario import LoadedScenario

F64 = NDArray[np.float64]
#: Shortest rotation period accepted [s] (:func:`_spin_model`).
MIN_PERIOD_S = 1e-3


@dataclasses.dataclass
class SpinAxisRun:
    """A finished search with what it was run on."""

    result: SpinAxisResult
    period_s: float
    spin_body_axis: list[float]
    scenario_axis: tuple[float, float] | None
    n_phases: int
    seconds: float
    source: str
    light: str = "sun"
    ranging_weight: float = 0.0
    time_utc: NDArray[np.datetime64] | None = None
    tracks: dict[str, tuple[F64, F64]] = dataclasses.field(default_factory=dict)
    period_bound: float | None = None  # None: the period was fixed


def phase_vector_track(
    epochs: EpochGeometry,
    spin_body_axis: list[float],
    *,
    ra_deg: float,
    dec_deg: float,
    phase_deg: float,
) -> tuple[F64, F64]:
    """Body-frame longitude and latitude [deg] of the phase vector at every epoch for one
    spin axis and phase (the observation track of the reference's Figure 18).

    Parameters
    ----------
    epochs
        Sun and observer directions and times of the epochs.
    spin_body_axis
        The spin axis in the body frame (3,).
    ra_deg, dec_deg, phase_deg
        The candidate: the axis (GCRS) and the rotation phase at the scenario start [deg].
    """
    from speclight.attitude.quaternion import quat_to_matrix
    from speclight.attitude.spin import spin_attitude
    from speclight.maps.map_geometry import lonlat_deg, map_coordinates

    if not (np.isfinite(ra_deg) and np.isfinite(dec_deg) and np.isfinite(phase_deg)):
        nan = np.full(epochs.t_s.size, np.nan)
        return nan, nan.copy()
    q = spin_attitude(epochs.t_s, ra_deg, dec_deg, epochs.period_s, phase_deg, spin_body_axis)
    r = quat_to_matrix(q)
    s = np.einsum("tji,tj->ti", r, epochs.sun_gcrs)
    o = np.einsum("tji,tj->ti", r, epochs.observer_gcrs)
    p, _, _ = map_coordinates(s, o)
    lon, lat = lonlat_deg(np.nan_to_num(p))
    bad = ~np.all(np.isfinite(p), axis=1)
    lon[bad], lat[bad] = np.nan, np.nan
    return lon, lat


def inertial_epochs(geo: Any, period_s: float) -> EpochGeometry:
    """The Sun and observer directions in GCRS of a pass's geometry (a
    :class:`~speclight.simulation.geometry_stage.Geometry`: they do not depend on the candidate
    spin axis), with the spin period [s]."""
    q = geo.quaternion_body_to_gcrs
    return EpochGeometry(
        quat_rotate(q, geo.sun_direction_body),
        quat_rotate(q, geo.observer_direction_body),
        geo.t_s,
        period_s,
    )


def _with_map_render(loaded: LoadedScenario, map_path: Path) -> LoadedScenario:
    sc = loaded.scenario
    render = sc.render.model_copy(update={"mode": "map", "map_file": str(map_path.resolve())})
    return dataclasses.replace(loaded, scenario=sc.model_copy(update={"render": render}))


def _spin_model(loaded: LoadedScenario, period_s: float | None) -> tuple[float, list[float], Any]:
    from speclight.scenario.sections_geometry import SpinAttitude

    att = loaded.scenario.attitude
    spin = att if isinstance(att, SpinAttitude) else None
    if period_s is None:
        if spin is None:
            raise InputError(
                f"no rotation period: the scenario's attitude is "
                f"'{att.model if att is not None else 'not given'}', not 'spin'; "
                "give period_s (e.g. from speclight period)",
                field="period_s",
            )
        period_s = spin.period_s
    if not (np.isfinite(period_s) and period_s >= MIN_PERIOD_S):
        raise InputError(
            f"period_s = {period_s} must be a number >= {MIN_PERIOD_S:g} [s] (a thousand "
            "turns per second: no satellite spins faster, and the rotation phase of shorter "
            "periods is lost to rounding over a pass)",
            field="period_s",
        )
    axis = list(spin.spin_body_axis) if spin is not None else [0.0, 0.0, 1.0]
    return float(period_s), [float(v) for v in axis], spin


def _candidate(answer: tuple[float, ...]) -> dict[str, float]:
    """``(RA, Dec, phase, ...)`` [deg] as :func:`phase_vector_track`'s keywords."""
    return {"ra_deg": answer[0], "dec_deg": answer[1], "phase_deg": answer[2]}


def spin_axis_measured(
    loaded: LoadedScenario,
    measured: str | Path,
    map_path: str | Path,
    *,
    period_s: float | None = None,
    grid_deg: float = 2.0,
    n_phases: int = 72,
    bands: list[str] | None = None,
    refine: bool = True,
    chunk: int = DEFAULT_AXIS_CHUNK,
    progress: Callable[[int, int], None] | None = None,
    light: str | None = None,
    ranging_weight: float | None = None,
    refine_method: str = "nelder-mead",
    period_bound: float | None = None,
    period_kind: str | None = None,
    period_check: bool = True,
) -> SpinAxisRun:
    """Search the spin axis of a measured pass against a reflectivity map (module doc).

    Parameters
    ----------
    loaded
        The scenario: orbit, observer, bands, ``attitude.spin_body_axis`` and
        ``attitude.period_s``.
    measured
        The measured pass: a speclight NetCDF or a CSV of band count rates.
    map_path
        The reflectivity map of the target (``speclight reflectivity-map``).
    period_s
        Rotation period [s] (default: the scenario's).
    grid_deg
        RA/Dec grid step [deg], 0.01..90.
    n_phases
        Rotation phases tried per axis.
    bands
        Bands to use (default: all the scenario's).
    refine
        Refine the best candidate locally.
    chunk
        Axes per lookup call (memory, not the result).
    progress
        Called with (done, total) axes, or None.
    light
        ``sun`` or ``laser`` (coaxial, the map's phase-0 slice); default: what the data have.
    ranging_weight
        Weight of the range-offset term (0: off); default 1 where the data and the map have
        range offsets.
    refine_method, period_bound
        The refinement's method and, for a free period, the fraction by which it may differ
        (:func:`.spin_axis_core.spin_axis_search`).
    period_kind
        What the period is (:mod:`.spin_axis_period`): ``sidereal``, ``synodic`` (a light
        curve's, e.g. from ``speclight period``) or ``auto``; default ``auto`` for a given
        ``period_s``, ``sidereal`` for the scenario's.
    period_check
        With a fixed period: warn where another period within 8 % fits better
        (:mod:`.spin_axis_period_check`).

    Returns
    -------
    SpinAxisRun
        The search's result, the light, the ranging weight and the time taken.
    """
    from speclight.estimate.inputs.geometry_match import check_scenario_sees
    from speclight.estimate.inputs.measured import read_measured
    from speclight.estimate.inputs.reflectance_factors import read_reflectance_factors
    from speclight.estimate.spin_axis.spin_axis_limits import check_search_cost
    from speclight.estimate.spin_axis.spin_axis_period import check_period_kind
    from speclight.estimate.spin_axis.spin_axis_refine import check_refine_options
    from speclight.maps.map_lookup import check_map_matches
    from speclight.simulation.geometry_stage import scenario_geometry
    from speclight.simulation.radiometry import wavelength_grid_nm

    check_search_options(grid_deg, n_phases)
    check_refine_options(refine_method, period_bound)
    if period_kind is None:
        period_kind = "sidereal" if period_s is None else "auto"
    check_period_kind(period_kind)
    period, body_axis, spin = _spin_model(loaded, period_s)
    map_path = Path(map_path)
    bmap = load_band_map(map_path)
    names = [b.name for b in loaded.scenario.instrument.bands]
    check_map_matches(bmap.header, wavelength_grid_nm(loaded.scenario.spectrum), names)
    chosen = list(names) if not bands else list(bands)
    for b in chosen:
        if b not in names:
            raise InputError(
                f"band '{b}' is not a band of the scenario and map ({', '.join(names)})",
                field="bands",
            )
    is_csv = Path(measured).suffix.lower() not in (".nc", ".nc4", ".netcdf", ".h5")
    if is_csv:  # before the CSV's rates are turned into factors with the scenario's geometry
        lc = read_measured(measured)
        sun = loaded.scenario.illumination.sun
        check_scenario_sees(
            loaded, measured, lc.time_utc[np.isfinite(lc.rate_per_s).any(axis=1)],
            light or ("sun" if sun else "laser"),
        )  # fmt: skip
    rf = read_reflectance_factors(
        measured, _with_map_render(loaded, map_path) if is_csv else loaded, light=light
    )
    if rf.bands.band_names != names:
        raise InputError(
            f"the measured bands {rf.bands.band_names} are not the scenario's {names}",
            field="MEASURED",
        )
    cols = [names.index(b) for b in chosen]
    y = rf.factor[:, cols]
    if not is_csv:
        check_scenario_sees(loaded, measured, rf.time_utc[np.any(np.isfinite(y), 1)], rf.light)
    geo = scenario_geometry(loaded, rf.time_utc)
    epochs = inertial_epochs(geo, period)
    lit = geo.sunlit_fraction > 0 if rf.light == "sun" else np.ones(y.shape[0], dtype=bool)
    y = np.where(geo.observable[:, None] & lit[:, None], y, np.nan)
    offsets = None if is_csv else measured_offsets(measured, rf.time_utc.size)
    if ranging_weight is None and not map_has_offsets(map_path):
        offsets = None  # automatic: ranging only where the map has offsets too
    weight = check_ranging_weight(ranging_weight, offsets)
    t0 = time.perf_counter()
    laser = None
    ranged = weight is None or weight > 0
    if rf.light == "laser" or ranged:
        from speclight.estimate.spin_axis.spin_axis_ranging import laser_band_map, laser_kernel

        kernel = laser_kernel(rf.bands.response[cols], rf.bands.wavelength_nm, rf.source_W_m2_nm)
        laser = laser_band_map(map_path, kernel, need_offsets=ranged)
    if rf.light == "laser":
        from speclight.estimate.spin_axis.spin_axis_ranging import coaxial

        assert laser is not None
        epochs = coaxial(epochs)
        rates = laser.intensity_W_sr_nm[..., : len(cols)]
        sub = dataclasses.replace(laser, intensity_W_sr_nm=np.ascontiguousarray(rates))
    else:
        rates = bmap.intensity_W_sr_nm[..., cols]
        sub = dataclasses.replace(bmap, intensity_W_sr_nm=np.ascontiguousarray(rates))
    header = sub.header
    check_search_cost(
        header.nside, header.phase_angle_deg.size, header.roll_deg.size, grid_deg, n_phases,
        y.shape[0], len(cols), ranging=ranged and laser is not None and offsets is not None,
    )  # fmt: skip
    ranging = None
    if ranged and laser is not None and offsets is not None:
        from speclight.estimate.spin_axis.spin_axis_ranging import RangingTerm

        ranging = RangingTerm(
            laser,
            spin_frame_map(laser, body_axis, n_phases),
            offsets[:, cols],
            weight,
            shares_rates=rf.light == "laser",
        )
    sfm = spin_frame_map(sub, body_axis, n_phases)
    result = spin_axis_search(
        sub,
        sfm,
        epochs,
        y,
        chosen,
        grid_deg,
        body_axis,
        chunk,
        progress,
        refine,
        ranging,
        refine_method,
        period_bound,
        period_kind,
        period_check,
    )
    seconds = time.perf_counter() - t0
    refined_epochs = epochs
    if np.isfinite(result.refined_period_s):
        refined_epochs = dataclasses.replace(epochs, period_s=result.refined_period_s)
    tracks = {
        "best": phase_vector_track(epochs, body_axis, **_candidate(result.best)),
        "refined": phase_vector_track(refined_epochs, body_axis, **_candidate(result.refined)),
    }
    truth = None
    if spin is not None:
        truth = (spin.spin_axis_ra_deg % 360.0, spin.spin_axis_dec_deg)
        # coaxial lasers: the phase vector is the observer direction
        pv = geo.phase_vector_body if rf.light == "sun" else geo.observer_direction_body
        tracks["scenario"] = (
            np.degrees(np.arctan2(pv[:, 1], pv[:, 0])) % 360.0,
            np.degrees(np.arcsin(np.clip(pv[:, 2], -1.0, 1.0))),
        )
    return SpinAxisRun(
        result,
        period,
        body_axis,
        truth,
        n_phases,
        seconds,
        rf.source,
        rf.light,
        result.ranging_weight,
        rf.time_utc,
        tracks,
        period_bound,
    )
