"""SHAPE.nc: the dataset ``speclight shape`` writes (variables and units: docs/shape.md).

Dimensions: ``period`` (trial periods), ``lambda`` and ``beta`` (the pole grid),
``solution`` (``best``, ``mirror``, then the other refined minima), ``facet``, ``xyz``,
``point`` (the fitted points), ``sample`` (bootstrap draws) and, with several bands,
``band``. Attributes of the best solution: ``period_h``, ``pole_lambda_deg``,
``pole_beta_deg`` (ecliptic J2000), their standard deviations, and where the mirror pole fits
as well ``mirror_lambda_deg``, ``mirror_beta_deg``; the null tests' verdicts.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from speclight.estimate.shape.convex_fit import ConvexSolution
from speclight.estimate.shape.shape_run import NULL_P_VALUE, ShapeRun
from speclight.estimate.shape.uncertainty import ambiguity_bound, covariance


def _var(dims: tuple[str, ...], values: Any, units: str, long_name: str) -> xr.Variable:
    return xr.Variable(dims, np.asarray(values), {"units": units, "long_name": long_name})


def verdict(run: ShapeRun) -> str:
    """What the data constrain, in words."""
    if not run.shape_constrained:
        return (
            f"the data do not constrain a shape, pole or period: the fit is no better "
            f"than a sphere (F-test p = {run.shape_p:.3g} >= {NULL_P_VALUE:g})"
        )
    parts = ["shape constrained"]
    parts.append(
        "pole constrained"
        if run.pole_constrained
        else "the pole is not constrained (the pole map is flat)"
    )
    parts.append(
        "period constrained"
        if run.period_constrained
        else "the period is not constrained (the period scan is flat)"
    )
    if run.mirror_reported:
        m = run.mirror
        parts.append(f"the mirror pole ({m.lambda_deg:.0f}, {m.beta_deg:.0f}) fits as well")
    elif not run.mirror_is_minimum:
        parts.append("the mirror pole is not a minimum")
    for other in run.equivalent_minima:
        parts.append(f"the pole ({other.lambda_deg:.0f}, {other.beta_deg:.0f}) fits as well")
    return "; ".join(parts)


def shape_dataset(run: ShapeRun, obj_file: str | None = None) -> xr.Dataset:
    """The dataset of a shape run (module doc)."""
    d = run.inputs.data
    unit = run.inputs.unit
    sols: list[ConvexSolution] = [run.best, run.mirror, *run.others]
    covs = [run.cov, run.mirror_cov, *(covariance(run.model, s) for s in run.others)]
    names = ["best", "mirror", *(f"minimum_{k + 2}" for k in range(len(run.others)))]
    fitted = run.model.fitted(run.best.theta)
    area_unit = "m2" if unit == "m2 sr-1" else "1"
    v = {
        "chi2_period": _var(
            ("period",), run.scan.chi2, "1", "chi-square of the best fit at each trial period"
        ),
        "fitted_period": _var(
            ("period",), run.scan.fitted_period_h, "h", "period each trial's fit converged to"
        ),
        "chi2_pole": _var(
            ("beta", "lambda"),
            run.poles.chi2,
            "1",
            "chi-square with the pole held at each grid point (coarse facets)",
        ),
        "solution_period": _var(
            ("solution",), [s.period_h for s in sols], "h", "sidereal rotation period"
        ),
        "solution_period_std": _var(
            ("solution",),
            [c.period_h for c in covs],
            "h",
            "standard deviation of the period (covariance)",
        ),
        "solution_lambda": _var(
            ("solution",), [s.lambda_deg for s in sols], "degree", "pole ecliptic longitude (J2000)"
        ),
        "solution_beta": _var(
            ("solution",), [s.beta_deg for s in sols], "degree", "pole ecliptic latitude (J2000)"
        ),
        "solution_lambda_std": _var(
            ("solution",),
            [c.lambda_deg for c in covs],
            "degree",
            "standard deviation of the pole longitude",
        ),
        "solution_beta_std": _var(
            ("solution",),
            [c.beta_deg for c in covs],
            "degree",
            "standard deviation of the pole latitude",
        ),
        "solution_chi2": _var(("solution",), [s.chi2 for s in sols], "1", "chi-square"),
        "facet_normal": _var(
            ("facet", "xyz"),
            run.model.normals,
            "1",
            "facet outward unit normal, body frame (z: the pole)",
        ),
        "facet_area": _var(
            ("facet",),
            run.best.areas,
            area_unit,
            "facet area times albedo (the EGI) of the best solution",
        ),
        "facet_area_std": _var(
            ("facet",),
            run.best.areas * run.cov.log_area,
            area_unit,
            "standard deviation of the facet area (covariance)",
        ),
        "time_jd": _var(("point",), d.time_jd, "d", "light-time corrected epoch (Julian date)"),
        "light_curve": _var(("point",), d.curve, "1", "index of the point's light curve"),
        "brightness": _var(("point",), d.brightness, unit, "measured brightness"),
        "brightness_sigma": _var(("point",), d.sigma, unit, "its standard deviation"),
        "brightness_fit": _var(
            ("point",), fitted, unit, "brightness of the best solution (scaled per relative curve)"
        ),
        "phase_angle": _var(("point",), d.phase_angle_deg, "degree", "solar phase angle"),
        "sample_period": _var(("sample",), run.samples[:, 2], "h", "bootstrap period"),
        "sample_lambda": _var(("sample",), run.samples[:, 0], "degree", "bootstrap pole longitude"),
        "sample_beta": _var(("sample",), run.samples[:, 1], "degree", "bootstrap pole latitude"),
        "sample_facet_area": _var(
            ("sample", "facet"), run.sample_areas, area_unit, "bootstrap facet areas (the EGI)"
        ),
    }
    coords = {
        "period": ("period", run.scan.trial_period_h, {"units": "h", "long_name": "trial period"}),
        "lambda": (
            "lambda",
            run.poles.lambda_deg,
            {"units": "degree", "long_name": "pole ecliptic longitude of the grid"},
        ),
        "beta": (
            "beta",
            run.poles.beta_deg,
            {"units": "degree", "long_name": "pole ecliptic latitude of the grid"},
        ),
        "solution": ("solution", names),
        "xyz": ("xyz", ["x", "y", "z"]),
    }
    if run.band_factor is not None:
        v["facet_band_area"] = _var(
            ("facet", "band"),
            run.band_factor,
            area_unit,
            "facet area times its albedo in each band",
        )
        coords["band"] = ("band", run.inputs.band_names)
    if run.materials is not None:
        v["facet_material_area"] = _var(
            ("facet", "material"),
            run.materials[1],
            "m2",
            "each material's area on the facet (NNLS of the facet's band spectrum)",
        )
        coords["material"] = ("material", run.materials[0])
    ds = xr.Dataset(v, coords=coords)
    ds.attrs.update(_attrs(run, obj_file))
    return ds


def _attrs(run: ShapeRun, obj_file: str | None) -> dict[str, Any]:
    b, c = run.best, run.cov
    a: dict[str, Any] = {
        "title": "speclight shape: convex inversion (EGI), sidereal period and pole",
        "period_h": b.period_h,
        "period_std_h": c.period_h,
        "pole_lambda_deg": b.lambda_deg,
        "pole_beta_deg": b.beta_deg,
        "pole_lambda_std_deg": c.lambda_deg,
        "pole_beta_std_deg": c.beta_deg,
        "pole_std_deg": c.pole_deg,
        "frame": "ecliptic J2000",
        "chi2": b.chi2,
        "residual_scale": c.residual_scale,
        "mirror_chi2": run.mirror.chi2,
        "mirror_is_minimum": int(run.mirror_is_minimum),
        "ambiguity_chi2": ambiguity_bound(c),
        "shape_p_value": run.shape_p,
        "shape_constrained": int(run.shape_constrained),
        "pole_constrained": int(run.pole_constrained),
        "period_constrained": int(run.period_constrained),
        "verdict": verdict(run),
        "law": run.law.name,
        "nside": run.options.nside,
        "search_nside": run.options.search_nside,
        "t0_jd": run.model.t0_jd,
        "n_points": run.inputs.data.n_points,
        "n_curves": run.inputs.data.n_curves,
        "source": run.inputs.source,
        "seconds": run.seconds,
    }
    if run.mirror_reported:
        a["mirror_lambda_deg"] = run.mirror.lambda_deg
        a["mirror_beta_deg"] = run.mirror.beta_deg
    a["poles_fitting_as_well"] = len(run.equivalent_minima)
    if run.samples.size:
        a["bootstrap_period_std_h"] = float(np.std(run.samples[:, 2], ddof=1))
        a["bootstrap_lambda_std_deg"] = float(np.std(run.samples[:, 0], ddof=1))
        a["bootstrap_beta_std_deg"] = float(np.std(run.samples[:, 1], ddof=1))
        areas = run.sample_areas
        if not np.any(run.inputs.data.calibrated):  # the shares, as facet_area_std
            areas = areas / areas.sum(axis=1, keepdims=True)
        a["bootstrap_area_std"] = float(np.median(np.std(np.log(areas), axis=0, ddof=1)))
    if obj_file is not None:
        a["obj_file"] = obj_file
    return a
