"""``speclight fit``: a scenario's simulation fitted to measured light curves (docs/fit.md).

The scenario is simulated at the measured epochs (orbit and attitude once; with roughness
free, reflection -> atmosphere -> instrument once per distinct roughness value on the same
geometry) and :mod:`speclight.estimate.fitting.fit` fits a scale per band (and the roughness of
every rough material). Epochs are used where the measurement and the simulation are finite
and the simulation flags none of ``orbit_failed``, ``below_min_elevation``,
``in_earth_shadow``, ``render_failed`` (penumbra epochs are kept: the model dims them).

**Albedo.** ``albedo_j = scale_j x rho_j``, with ``rho_j`` the scenario's own reflectance of
the target in band j: each part's material reflectance (``reflectance``; for ``plastic`` its
``diffuse_reflectance``; Fresnel reflectances at normal incidence) averaged over the parts
weighted by their surface area, then averaged over the band with the weights of the photons
the measurement detects (the pass's mean Sun at the aperture x band response x optics x QE x
wavelength: :func:`speclight.estimate.inputs.band_albedo.band_albedo`, the one definition
shared with ``upsample``). For a constant reflectance r it is
``r x scale``. With several materials one scale per band multiplies all of them: the albedo
is then the area-weighted mean, a summary rather than a per-material value.
"""

from __future__ import annotations

import math
import sys
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight import schema
from speclight.errors import InputError
from speclight.estimate.fitting.fit import F64
from speclight.estimate.fitting.fit_bins import EpochBins
from speclight.estimate.fitting.fit_inputs import band_reflectance, noise_of
from speclight.estimate.fitting.fit_quality import (
    CLIP_SIGMA,
    clipped_scales,
    misfit_text,
    outlier_text,
    reduced_chi2,
)
from speclight.estimate.fitting.fit_run_roughness import (
    fit_rough_gradient,
    fit_rough_slsqp,
    roughness_problems,
)
from speclight.estimate.fitting.noise_model import Likelihood
from speclight.estimate.inputs.measured import MeasuredLightCurve
from speclight.scenario import LoadedScenario
from speclight.scenario.overrides import replace_fields

FREE_CHOICES = ("albedo", "roughness")
#: ``--method``: SLSQP with central differences (and a scan), or analytic gradients.
METHODS = ("slsqp", "gradient")
ROUGH_BSDFS = ("beckmann", "ggx", "plastic")
_SKIP = (
    schema.FLAG_ORBIT_FAILED
    | schema.FLAG_BELOW_MIN_ELEVATION
    | schema.FLAG_IN_SHADOW
    | schema.FLAG_RENDER_FAILED
    | schema.FLAG_DAYLIGHT
)


@dataclass
class FitResult:
    """A fit's numbers (``to_json`` gives FIT.json) and the curves of its figure."""

    band_names: list[str]
    albedo: F64
    albedo_std: F64
    scale: F64
    scale_std: F64
    rms_percent_of_mean_band: F64
    roughness: dict[str, tuple[float, float]]
    rms_percent_of_mean: float
    rms_percent_of_total: float
    n_epochs: int
    method: str
    converged: bool
    message: str
    time_utc: NDArray[np.datetime64]
    measured_per_s: F64
    fitted_per_s: F64
    extra: dict[str, Any] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        """FIT.json (docs/fit.md); NaN becomes ``null``."""
        bands = {
            name: {
                "albedo": _num(self.albedo[j]),
                "albedo_std": _num(self.albedo_std[j]),
                "scale": _num(self.scale[j]),
                "scale_std": _num(self.scale_std[j]),
                "rms_percent_of_mean": _num(self.rms_percent_of_mean_band[j]),
            }
            for j, name in enumerate(self.band_names)
        }
        rough = {k: {"value": _num(v), "std": _num(s)} for k, (v, s) in self.roughness.items()}
        return {
            "bands": bands,
            "roughness": rough,
            "rms_percent_of_mean": _num(self.rms_percent_of_mean),
            "rms_percent_of_total": _num(self.rms_percent_of_total),
            "n_epochs": self.n_epochs,
            "method": self.method,
            "converged": self.converged,
            "message": self.message,
            **self.extra,
        }


def _num(x: float) -> float | None:
    x = float(x)
    return x if math.isfinite(x) else None


def check_free(free: Sequence[str]) -> tuple[str, ...]:
    """The parameters to fit, checked: one or more of :data:`FREE_CHOICES`."""
    names = tuple(free)
    if not names or any(p not in FREE_CHOICES for p in names):
        raise InputError(
            f"free = {names!r}: give one or more of {', '.join(FREE_CHOICES)}", field="free"
        )
    return names


def check_method(method: str) -> str:
    """The roughness fit's method, checked: one of :data:`METHODS`."""
    if method not in METHODS:
        raise InputError(f"method = {method!r}: give one of {', '.join(METHODS)}", field="method")
    return method


def rough_materials(loaded: LoadedScenario) -> list[str]:
    """Names of the scenario's materials with a microfacet roughness."""
    target = loaded.scenario.target
    if target is None:
        return []
    return [n for n, m in target.materials.items() if m.bsdf in ROUGH_BSDFS and m.roughness]


def _for_fitting(loaded: LoadedScenario) -> LoadedScenario:
    """The scenario without what a fit does not use (noise draws, saved images)."""
    return replace_fields(loaded, {"instrument.noise": None, "render.save_images_at": []})


def fit_scenario(
    loaded: LoadedScenario,
    measured: MeasuredLightCurve,
    *,
    free: tuple[str, ...] = ("albedo",),
    bin_s: float | None = None,
    progress: bool = False,
    method: str = "slsqp",
    scan: bool = True,
    clip_sigma: float | None = CLIP_SIGMA,
) -> FitResult:
    """Fit the scenario's band albedos (and roughness) to measured count rates.

    Parameters
    ----------
    loaded
        The scenario: its reflectance and roughness values are the start of the fit.
    measured
        Measured light curves (:func:`speclight.estimate.read_measured`); its bands must
        include every band of the scenario.
    free
        Parameters to fit: ``albedo``, ``roughness`` or both.
    bin_s
        Average the measurements into bins of this many seconds, shorter than their time
        span, and the model over the same epochs and bands (:mod:`.fit_bins`: the model is
        simulated at every measured epoch; the flagged ones are left out of both).
    progress
        Show render progress and the roughness iterations on a terminal.
    method
        How the roughness is fitted: ``slsqp`` (central differences, after a scan) or
        ``gradient`` (analytic derivatives of the single-scattering render,
        :mod:`speclight.estimate.fitting.gradient_fit`). The albedos are in closed form either way.
    scan
        Scan the bounds before the local method (:mod:`.roughness_scan`; ``False`` starts
        it at the scenario's roughness).
    clip_sigma
        Leave out measurements more than this many robust sigmas from the fit, and say so
        (:mod:`.fit_quality`); 0 or None keeps every one.
    """
    from speclight.simulation import simulate

    check_free(free)
    check_method(method)
    if (
        clip_sigma is not None
        and clip_sigma != 0
        and not (math.isfinite(clip_sigma) and clip_sigma >= 3)
    ):
        raise InputError(
            f"clip_sigma = {clip_sigma!r}: give a number of sigmas >= 3, or 0 to keep every "
            "measurement",
            field="clip_sigma",
        )
    clip_sigma = clip_sigma or None
    sc = loaded.scenario
    if sc.target is None:
        raise InputError("the scenario has no target to fit", field="target")
    names = [b.name for b in sc.instrument.bands]
    if not names:
        raise InputError("the scenario has no instrument bands to fit", field="instrument.bands")
    lc = measured.select_bands(names)
    if bin_s is not None:
        from speclight.estimate.inputs.cost_limits import check_bin_s

        check_bin_s(bin_s, lc.time_utc)
    rough = rough_materials(loaded) if "roughness" in free else []
    if "roughness" in free and not rough:
        raise InputError(
            "free=roughness: the scenario has no material with a roughness "
            f"(bsdf {', '.join(ROUGH_BSDFS)})",
            field="free",
        )
    if rough and method == "gradient":
        from speclight.estimate.fitting.roughness_gradient import gradient_problems

        problems = gradient_problems(loaded, rough)
        if problems:
            raise InputError(
                "method='gradient': " + "; ".join(problems) + " (use method='slsqp')",
                field="method",
            )
    base = _for_fitting(loaded)
    show = progress and sys.stderr.isatty()
    first = simulate(base, progress=show, time_utc=lc.time_utc)
    ds = first.dataset
    sigma = noise_of(loaded, lc, ds)
    usable = (ds["flags"].values.astype(np.int64) & _SKIP) == 0
    m = np.where(usable[:, None], lc.rate_per_s, np.nan)
    _check_some_usable(lc, m, ds, loaded)
    bins = None
    if bin_s is not None:
        bins = EpochBins.of(lc.time_utc, bin_s, np.isfinite(m))
    rho = band_reflectance(loaded, ds)
    notes: list[str] = []
    if rough:
        if method == "gradient":
            fit = fit_rough_gradient(
                base, first, m=m, sigma=sigma, rough=rough, fit_scale="albedo" in free,
                show=show, scan=scan, bins=bins, clip_sigma=clip_sigma,
            )  # fmt: skip
            method_text = (
                "gradient: least squares (trust region) over log roughness with the analytic "
                "Jacobian (variable projection), weighted least squares for scales"
            )
        else:
            fit = fit_rough_slsqp(
                base, first, m=m, sigma=sigma, rough=rough, fit_scale="albedo" in free,
                show=show, scan=scan, bins=bins, clip_sigma=clip_sigma,
            )  # fmt: skip
            method_text = (
                "SLSQP over roughness (variable projection), weighted least squares for scales"
            )
        model, scales = fit.model, fit.scales
        roughness = {
            n: (float(v), float(s))
            for n, v, s in zip(rough, fit.roughness, fit.roughness_std, strict=True)
        }
        notes += roughness_problems(rough, fit)
        extra = {"n_simulations": fit.n_simulations, "n_iterations": fit.n_iterations}
        drop, n_par = fit.outliers, len(rough)
    else:
        model = ds["count_rate"].transpose("time", "band").values.astype(float)
        model = np.where(usable[:, None], model, np.nan)
        if "albedo" not in free:
            raise InputError("`free` must include albedo or roughness", field="free")
        if bins is not None:
            model = bins.mean(model)
        m_fit, s_fit = (m, sigma) if bins is None else (bins.mean(m), sigma.binned(bins))
        scales, drop = clipped_scales(Likelihood(m_fit, s_fit), model, clip_sigma)
        roughness, extra, n_par = {}, {}, 0
        method_text = "weighted least squares (closed form; linear in albedo)"
    if bins is not None:
        m = bins.mean(m)
        lc = replace(lc, time_utc=bins.time_utc)
        method_text += f"; measurements and model averaged over the same {bin_s:g} s bins"
    notes += _scale_problems(names, scales.scale, scales.scale_std, scales.n_used)
    fitted = model * scales.scale[None, :]
    n_par += len(names) if "albedo" in free else 0
    notices = [
        text
        for text in (
            outlier_text(drop, lc.time_utc, names, clip_sigma or 0.0),
            misfit_text(float(np.sum(scales.chi2)), int(np.sum(scales.n_used)), n_par),
        )
        if text
    ]
    extra["n_outliers"] = int(np.count_nonzero(drop))
    extra["chi2_per_dof"] = _num(
        reduced_chi2(float(np.sum(scales.chi2)), int(np.sum(scales.n_used)), n_par)
    )
    m = np.where(drop, np.nan, m)
    result = _result(lc, names, rho, scales, roughness, m, fitted, method_text, notes, extra)
    if notices:
        result.message = "; ".join(([] if result.converged else [result.message]) + notices)
    return result


def _check_some_usable(lc: MeasuredLightCurve, m: F64, ds: Any, loaded: LoadedScenario) -> None:
    """Refuse measurements of which no entry can be fitted: none finite at an epoch where the
    scenario sees the target lit (the flags of ``ds`` say why not)."""
    if np.isfinite(m).any():
        return
    from speclight.estimate.inputs.cost_limits import time_span_text

    flags = ds["flags"].values.astype(np.int64)
    counts = ", ".join(
        f"{name} at {int(np.count_nonzero(flags & bit))}"
        for bit, name in schema.FLAG_MEANINGS.items()
        if bit & _SKIP and np.any(flags & bit)
    )
    t = loaded.scenario.time
    raise InputError(
        f"no measured rate can be fitted: none of the epochs {time_span_text(lc.time_utc)} "
        "has a finite rate where the scenario sees its target lit (flagged: "
        f"{counts or 'none; no rate is finite'}); the scenario's time window is "
        f"{t.start:%Y-%m-%dT%H:%M:%S} .. {t.stop:%Y-%m-%dT%H:%M:%S} UTC: give the "
        "scenario of this target, site and night",
        source=lc.source,
        field="MEASURED",
    )


def _scale_problems(names: list[str], scale: F64, std: F64, n_used: NDArray) -> list[str]:
    out = []
    for j, name in enumerate(names):
        if n_used[j] == 0:
            out.append(f"band '{name}' has no usable epochs (no finite, observable, lit data)")
        elif not np.isfinite(scale[j]) or not np.isfinite(std[j]):
            out.append(f"albedo of band '{name}' is not constrained (the model is zero there)")
        elif scale[j] < 0:
            out.append(f"albedo of band '{name}' came out negative ({scale[j]:.3g} x start)")
    return out


def _result(
    lc: MeasuredLightCurve,
    names: list[str],
    rho: F64,
    scales: Any,
    roughness: dict[str, tuple[float, float]],
    m: F64,
    fitted: F64,
    method: str,
    notes: list[str],
    extra: dict[str, Any],
) -> FitResult:
    used = np.isfinite(m) & np.isfinite(fitted)
    res = np.where(used, m - fitted, np.nan)
    with np.errstate(invalid="ignore", divide="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a band without data: NaN
        rms_band = np.sqrt(np.nanmean(res**2, axis=0)) / np.nanmean(np.where(used, m, np.nan), 0)
        rms_all = float(np.sqrt(np.nanmean(res**2)))
        mean_all = float(np.nanmean(np.where(used, m, np.nan)))
        total = float(np.nansum(np.where(used, m, np.nan)))
    return FitResult(
        band_names=names,
        albedo=rho * scales.scale,
        albedo_std=rho * scales.scale_std,
        scale=scales.scale,
        scale_std=scales.scale_std,
        rms_percent_of_mean_band=100.0 * rms_band,
        roughness=roughness,
        rms_percent_of_mean=100.0 * rms_all / mean_all if mean_all else math.nan,
        rms_percent_of_total=100.0 * rms_all / total if total else math.nan,
        n_epochs=int(np.count_nonzero(used.any(axis=1))),
        method=method,
        converged=not notes,
        message="; ".join(notes) if notes else "ok",
        time_utc=lc.time_utc,
        measured_per_s=np.where(used, m, np.nan),
        fitted_per_s=np.where(used, fitted, np.nan),
        extra={
            "band_reflectance_of_scenario": {n: _num(r) for n, r in zip(names, rho, strict=True)},
            **extra,
        },
    )


__all__ = [
    "FREE_CHOICES",
    "METHODS",
    "FitResult",
    "check_free",
    "check_method",
    "fit_scenario",
    "rough_materials",
]
