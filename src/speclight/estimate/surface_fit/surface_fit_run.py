"""``speclight fit SCENARIO OBSERVATIONS --free brdf[,attitude]``: the analytic BRDFs of a
target's surfaces (and a yaw offset) fitted to observed magnitudes (docs/surface-fit.md).

The observations are simulated as ``speclight compare`` simulates them
(:func:`~speclight.estimate.comparison.compare_run.site_runs`: one run per site, the
scenario's orbit or ``orbit: {observed: true}`` with an ``object`` column), once; the
fitted surfaces' lit, visible elements are kept (:mod:`.surface_records`) and the
magnitudes follow from the BRDF coefficients without another render
(:mod:`.surface_model`). With ``attitude`` free, the body is turned about its +z (nadir)
axis by each yaw of a grid (one simulation each), the BRDFs fitted at each, and the yaw
refined by a parabola through the profile's three lowest points.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight import schema
from speclight.errors import InputError
from speclight.estimate.comparison.compare_run import site_runs
from speclight.estimate.inputs.observations import FIELD, Observations
from speclight.estimate.surface_fit.robust_fit import (
    bootstrap_std,
    calibrated_std,
    night_halves,
    robust_fit,
)
from speclight.estimate.surface_fit.surface_fit_report import fit_summary, stats
from speclight.estimate.surface_fit.surface_model import SurfaceModel
from speclight.estimate.surface_fit.surface_parameters import FreeSurface, free_surfaces
from speclight.estimate.surface_fit.surface_records import SurfaceRecords, shading_records, yawed
from speclight.scenario import LoadedScenario

F64 = NDArray[np.float64]
I64 = NDArray[np.intp]
#: What ``free`` accepts.
FREE_CHOICES = ("brdf", "attitude")
#: Yaw offsets simulated for ``attitude`` [deg].
YAW_GRID_DEG = tuple(float(y) for y in np.arange(-20.0, 20.5, 5.0))
#: Rows whose simulation has one of these flags are not fitted.
EXCLUDED = (
    schema.FLAG_ORBIT_FAILED | schema.FLAG_BELOW_MIN_ELEVATION | schema.FLAG_IN_SHADOW
    | schema.FLAG_RENDER_FAILED | schema.FLAG_DAYLIGHT | schema.FLAG_ATTITUDE_UNDEFINED
)  # fmt: skip
#: A variable is constrained when its std is below this [dex] (log10 variables: a factor
#: of 2) or this fraction of its bounds' range (linear ones), and it is off its bounds.
MAX_STD_DEX = 0.3
MAX_STD_FRACTION = 0.1


@dataclass
class _Design:
    model: SurfaceModel
    used: NDArray[np.bool_]
    phase_deg: F64


def _design(
    loaded: LoadedScenario,
    obs: Observations,
    surfaces: list[FreeSurface],
    yaw_deg: float | None,
    progress: bool,
) -> _Design:
    n = obs.time_utc.size
    mag0, rf0, phase = np.full(n, np.nan), np.full(n, np.nan), np.full(n, np.nan)
    flags = np.full(n, schema.FLAG_ORBIT_FAILED, dtype=np.int64)
    row_epoch = np.zeros(n, dtype=np.int64)
    names = [s.name for s in surfaces]
    parts: list[SurfaceRecords] = []
    offset = 0
    adjust = None if yaw_deg is None else (lambda g: yawed(g, yaw_deg))
    for run in site_runs(loaded, obs, progress=progress, adjust=adjust):
        ds = run.result.dataset
        if "reflectance_factor" not in ds:
            raise InputError(
                "the scenario gives no band reflectance factor (no Sun, or no bands): a "
                "BRDF fit needs sunlit observations",
                source=loaded.source,
                field="illumination.sun",
            )
        mag0[run.rows] = ds["ab_magnitude"].values[run.epoch, run.band]
        rf0[run.rows] = ds["reflectance_factor"].values[run.epoch, run.band]
        flags[run.rows] = ds["flags"].values[run.epoch]
        phase[run.rows] = ds["phase_angle"].values[run.epoch]
        row_epoch[run.rows] = offset + run.epoch
        lit = (ds["flags"].values[run.epoch] & EXCLUDED) == 0
        epochs = np.unique(run.epoch[lit])
        geo = run.result.geometry
        parts.append(shading_records(run.scenario, geo, names, epochs).shifted(offset))
        offset += int(ds.sizes["time"])
    with np.errstate(invalid="ignore"):
        used = (
            np.isfinite(obs.magnitude) & np.isfinite(mag0) & (rf0 > 0) & ((flags & EXCLUDED) == 0)
        )
    if used.sum() < sum(len(s.free) for s in surfaces) + 1:
        raise InputError(
            f"{int(used.sum())} observations can be fitted (observed, simulated, sunlit, "
            f"above the minimum elevation in a dark sky), fewer than the "
            f"{sum(len(s.free) for s in surfaces)} BRDF coefficients + 1 to fit",
            source=obs.source,
            field=FIELD,
        )
    model = SurfaceModel(surfaces, SurfaceRecords.join(parts), row_epoch, mag0, rf0, offset)
    return _Design(model, used, phase)


@dataclass
class SurfaceFitResult:
    """The fit (SURFACES.json, docs/surface-fit.md) and the arrays of its figure."""

    summary: dict[str, Any]
    phase_angle_deg: F64
    residual_start_mag: F64
    residual_fit_mag: F64
    residual_cross_mag: F64
    used: NDArray[np.bool_]
    yaw_profile: list[tuple[float, float]] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    @property
    def converged(self) -> bool:
        return bool(self.summary["converged"])

    def to_json(self) -> dict[str, Any]:
        return self.summary


def _bounds(surfaces: list[FreeSurface]) -> tuple[F64, F64]:
    b = np.array([c.bounds for s in surfaces for c in s.free])
    return b[:, 0], b[:, 1]


def _constrained(
    std: F64, u: F64, surfaces: list[FreeSurface], bounds: tuple[F64, F64]
) -> list[str]:
    """Why each variable is not constrained ("" where it is)."""
    out = []
    lo, hi = bounds
    logs = [c.log10 for s in surfaces for c in s.free]
    for i, is_log in enumerate(logs):
        span = hi[i] - lo[i]
        limit = MAX_STD_DEX if is_log else MAX_STD_FRACTION * span
        if min(u[i] - lo[i], hi[i] - u[i]) < 1e-3 * span:
            out.append("at a bound of its range")
        elif not np.isfinite(std[i]):
            out.append("no observed magnitude changes with it")
        elif std[i] > limit:
            unit = " dex" if is_log else ""
            out.append(f"std {std[i]:.3g}{unit} > {limit:.3g}{unit}")
        else:
            out.append("")
    return out


def _yaw_profile(
    loaded: LoadedScenario, obs: Observations, surfaces: list[FreeSurface],
    grid: Sequence[float], progress: bool,
) -> tuple[float, float, list[tuple[float, float]], str]:  # fmt: skip
    """Best yaw [deg], its std [deg] (NaN: not constrained), the profile and a message."""
    bounds = _bounds(surfaces)
    centre = _design(loaded, obs, surfaces, 0.0, progress)
    rows = np.flatnonzero(centre.used)
    first = robust_fit(centre.model.magnitude, obs.magnitude, obs.magnitude_sigma, rows,
                       centre.model.u0, bounds)  # fmt: skip
    profile = []
    for yaw in grid:
        d = centre if yaw == 0.0 else _design(loaded, obs, surfaces, float(yaw), progress)
        r = np.flatnonzero(d.used & centre.used)
        f = robust_fit(d.model.magnitude, obs.magnitude, obs.magnitude_sigma, r, first.u,
                       bounds, first.tau_mag)  # fmt: skip
        profile.append((float(yaw), f.chi2))
    yaws = np.array([p[0] for p in profile])
    chi2 = np.array([p[1] for p in profile])
    i = int(np.argmin(chi2))
    if i in (0, yaws.size - 1):
        return float(yaws[i]), np.nan, profile, "yaw at the edge of its grid: not constrained"
    c2, c1, _ = np.polyfit(yaws[i - 1 : i + 2], chi2[i - 1 : i + 2], 2)
    if c2 <= 0:
        return float(yaws[i]), np.nan, profile, "yaw profile not convex: not constrained"
    best = float(np.clip(-c1 / (2 * c2), yaws[i - 1], yaws[i + 1]))
    scale = max(1.0, first.chi2 / first.dof)
    return best, float(np.sqrt(scale / c2)), profile, ""


def fit_surfaces(
    loaded: LoadedScenario,
    obs: Observations,
    free: Sequence[str] = ("brdf",),
    materials: list[str] | None = None,
    yaw_grid_deg: Sequence[float] = YAW_GRID_DEG,
    n_bootstrap: int = 40,
    seed: int = 0,
    progress: bool = False,
) -> SurfaceFitResult:
    """Fit the analytic BRDF coefficients of the target's surfaces to observed magnitudes.

    Parameters
    ----------
    loaded
        The scenario (``render.mode: single``); its coefficients are the fit's start.
    obs
        From :func:`~speclight.estimate.inputs.observations.read_observations`.
    free
        ``brdf`` and optionally ``attitude`` (a yaw offset about the body's +z axis).
    materials
        Keys of ``target.materials`` to fit (None: every analytic material).
    yaw_grid_deg
        Yaw offsets [deg] simulated for ``attitude``.
    n_bootstrap
        Resamplings of the rows for the bootstrap standard deviations (0: none; the
        Jacobian's are then reported unchecked).
    seed
        Of the bootstrap.
    progress
        Progress bars on a terminal.
    """
    sc = loaded.scenario
    unknown = [f for f in free if f not in FREE_CHOICES]
    if unknown or "brdf" not in free:
        raise InputError(
            f"free = {','.join(free)!r}: a surface fit takes brdf or brdf,attitude",
            field="free",
        )
    if sc.target is None or sc.render.mode != "single" or sc.target.articulation:
        raise InputError(
            "a BRDF fit renders the target's surfaces once in single-scattering mode: the "
            "scenario needs a target, render.mode: single and no target.articulation",
            source=loaded.source,
            field="render.mode",
        )
    if n_bootstrap < 0 or n_bootstrap == 1:
        raise InputError(f"n_bootstrap = {n_bootstrap} must be 0 or >= 2", field="n_bootstrap")
    surfaces = free_surfaces(sc.target.materials, materials)
    bounds = _bounds(surfaces)
    yaw: float | None = None
    yaw_std, yaw_message = np.nan, ""
    profile: list[tuple[float, float]] = []
    if "attitude" in free:
        yaw, yaw_std, profile, yaw_message = _yaw_profile(
            loaded, obs, surfaces, yaw_grid_deg, progress
        )
    d = _design(loaded, obs, surfaces, yaw, progress)
    rows = np.flatnonzero(d.used)
    m, sigma = d.model, obs.magnitude_sigma
    fit = robust_fit(m.magnitude, obs.magnitude, sigma, rows, m.u0, bounds)
    jac_std = np.sqrt(np.clip(np.diag(fit.cov), 0.0, None))
    boot = (
        bootstrap_std(m.magnitude, obs.magnitude, sigma, rows, fit, bounds, n_bootstrap, seed)
        if n_bootstrap
        else np.full(fit.u.size, np.nan)
    )
    std, how = (
        calibrated_std(jac_std, boot) if n_bootstrap else (jac_std, ["jacobian"] * fit.u.size)
    )
    why = _constrained(std, fit.u, surfaces, bounds)
    with np.errstate(invalid="ignore", divide="ignore"):
        start_mag = m.magnitude(m.u0)
        fit_mag = m.magnitude(fit.u)
    cross = np.full(obs.time_utc.size, np.nan)
    first, second, split = night_halves(obs.time_utc[rows], obs.longitude_deg[rows])
    halves = (first, second)
    cv = []
    for train, test in (halves, halves[::-1]):
        f = robust_fit(m.magnitude, obs.magnitude, sigma, rows[train], m.u0, bounds)
        cross[rows[test]] = obs.magnitude[rows[test]] - m.magnitude(f.u)[rows[test]]
        cv.append(stats(obs.magnitude[rows[test]], m.magnitude(f.u)[rows[test]]))
    summary = fit_summary(
        obs, surfaces, fit, jac_std, boot, std, how, why, rows, start_mag, fit_mag,
        cross, cv, split, (yaw, yaw_std, yaw_message), n_bootstrap,
    )  # fmt: skip
    residual_start = np.where(d.used, obs.magnitude - start_mag, np.nan)
    residual_fit = np.where(d.used, obs.magnitude - fit_mag, np.nan)
    return SurfaceFitResult(summary, d.phase_deg, residual_start, residual_fit, cross, d.used,
                            profile)  # fmt: skip
