"""AXIS.nc, what ``speclight spin-axis`` writes (docs/spin-axis.md "AXIS.nc"): the misfit
surface, the answers, the tracks, the confidence."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from speclight.estimate.spin_axis.spin_axis_core import MIRROR_SEP_DEG, SpinAxisResult
from speclight.estimate.spin_axis.spin_axis_run import SpinAxisRun


def axis_dataset(run: SpinAxisRun, map_path: str, scenario_source: str) -> xr.Dataset:
    """AXIS.nc (docs/spin-axis.md): ``error(ra, dec)``, ``best_phase(ra, dec)`` and the answers."""
    r = run.result
    ds = xr.Dataset(
        {
            "error": (("ra", "dec"), r.error),
            "best_phase": (("ra", "dec"), r.best_phase_deg),
        },
        coords={"ra": r.ra_deg, "dec": r.dec_deg, "band": r.band_names},
    )
    if run.time_utc is not None and run.tracks:
        names = list(run.tracks)
        ds = ds.assign_coords(time=run.time_utc, solution=names)
        lon = np.stack([run.tracks[n][0] for n in names], axis=1)
        lat = np.stack([run.tracks[n][1] for n in names], axis=1)
        ds["track_lon"] = (("time", "solution"), lon, {"units": "deg"})
        ds["track_lat"] = (("time", "solution"), lat, {"units": "deg"})
        ds["track_lon"].attrs["long_name"] = "body-frame longitude of the phase vector"
        ds["track_lat"].attrs["long_name"] = "body-frame latitude of the phase vector"
    ds["ra"].attrs["units"] = "deg"
    ds["dec"].attrs["units"] = "deg"
    ds["best_phase"].attrs.update(
        units="deg", long_name="rotation phase at the scenario start minimising the misfit"
    )
    ds["error"].attrs.update(
        units="1",
        long_name="misfit minimised over the phase: mean over epochs and bands of the squared "
        "difference of the light curves each divided by its mean",
    )
    attrs: dict[str, Any] = {}
    for key, val in (("best", r.best), ("mirror", r.mirror), ("refined", r.refined)):
        attrs[f"{key}_ra_deg"], attrs[f"{key}_dec_deg"] = val[0], val[1]
        attrs[f"{key}_phase_deg"], attrs[f"{key}_error"] = val[2], val[3]
    if run.scenario_axis is not None:
        attrs["scenario_ra_deg"], attrs["scenario_dec_deg"] = run.scenario_axis
    refined = bool(np.isfinite(r.refined[0]))
    attrs.update(
        refine_method=r.refine_method if refined else "none",
        refine_note=r.refine_note or "refined from the grid's best cell (and the mirror's)",
        mirror_note="the lowest local minimum farther than mirror_min_separation_deg from the "
        "best cell"
        if np.isfinite(r.mirror[0])
        else "no local minimum of the misfit farther than mirror_min_separation_deg from the "
        "best cell: mirror_* is NaN",
        refine_misfit_evaluations=r.refine_n_misfit,
        refine_gradient_evaluations=r.refine_n_gradient,
        period_free=int(run.period_bound is not None),
        refined_period_s=r.refined_period_s,
        period_kind=r.period_kind,
    )
    for kind, err in r.period_kind_errors.items():
        attrs[f"{kind}_best_error"] = err
    if run.period_bound is not None:
        attrs["period_bound"] = run.period_bound
    ds = _with_confidence(ds, r)
    _with_period_check(ds, r)
    attrs.update(
        period_s=run.period_s,
        spin_body_axis=np.asarray(run.spin_body_axis, dtype=float),
        n_phases=run.n_phases,
        grid_deg=float(360.0 / r.ra_deg.size),
        n_epochs=r.n_epochs,
        mirror_min_separation_deg=MIRROR_SEP_DEG,
        normalisation="each band's light curve divided by its mean over the epochs",
        phase_convention="phase of the rotation about spin_body_axis at the scenario start, "
        "from the ascending node of the spin plane (attitude model spin)",
        measured_source=run.source,
        light=run.light,
        ranging_weight=run.ranging_weight,
        map_file=map_path,
        scenario_source=scenario_source,
        seconds=run.seconds,
    )
    ds.attrs.update(attrs)
    return ds


#: AXIS.nc attributes of :class:`.spin_axis_confidence.AxisConfidence` (docs/spin-axis.md).
CONFIDENCE_ATTRS = (
    "sigma_axis_deg", "sigma_east_deg", "sigma_north_deg", "correlation_east_north",
    "sigma_phase_deg", "sigma_period_s", "misfit_per_chi2", "region68_fraction",
    "region95_fraction", "region95_max_sep_deg", "contrast", "noise_floor", "noise_ratio",
    "hac_lag",
)  # fmt: skip


def _with_confidence(ds: xr.Dataset, r: SpinAxisResult) -> xr.Dataset:
    """``delta_chi2(ra, dec)`` and the confidence attributes (NaN without a refinement)."""
    c = r.confidence
    for name in CONFIDENCE_ATTRS:
        ds.attrs[name] = float("nan") if c is None else getattr(c, name)
    ds.attrs["sigma_method"] = "none" if c is None else c.method
    ds.attrs["axis_constrained"] = int(c is not None and c.constrained)
    ds.attrs["axis_note"] = "not refined: no sigmas" if c is None else c.note
    scale = float("nan") if c is None else c.misfit_per_chi2
    finite = np.isfinite(r.error)
    e_min = float(np.min(r.error[finite])) if finite.any() else float("nan")
    ds["delta_chi2"] = (("ra", "dec"), (r.error - e_min) / scale)
    ds["delta_chi2"].attrs.update(
        units="1",
        long_name="rise of the misfit over the best cell in units of chi-square (the "
        "sandwich covariance's misfit per unit chi-square); <= 2.30: 68 % region, <= 5.99: "
        "95 % region",
    )
    return ds


#: AXIS.nc attributes of :class:`.spin_axis_period_check.PeriodCheck`, each ``period_check_``
#: and the field's name (docs/spin-axis.md).
PERIOD_CHECK_ATTRS = (
    "preferred_period_s", "preferred_misfit", "given_misfit", "preferred_ra_deg",
    "preferred_dec_deg", "separation_deg", "z", "n_periods",
)  # fmt: skip


def _with_period_check(ds: xr.Dataset, r: SpinAxisResult) -> None:
    """``period_check_*`` attributes: ``period_check`` is ``warned``, ``passed`` or ``not
    run`` (a free period, no refinement, a flat surface or turned off)."""
    c = r.period_check
    if c is None:
        ds.attrs["period_check"] = "not run"
        return
    ds.attrs["period_check"] = "warned" if c.warn else "passed"
    ds.attrs["period_check_note"] = c.note
    for name in PERIOD_CHECK_ATTRS:
        ds.attrs[f"period_check_{name}"] = getattr(c, name)
