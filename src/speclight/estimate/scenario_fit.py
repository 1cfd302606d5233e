"""``speclight fit``: a scenario's simulation fitted to measured light curves (docs/fit.md).

The scenario is simulated at the measured epochs (orbit and attitude once; with roughness
free, reflection -> atmosphere -> instrument once per distinct roughness value on the same
geometry) and :mod:`speclight.estimate.fit` fits a scale per band (and the roughness of
every rough material). Epochs are used where the measurement and the simulation are finite
and the simulation flags none of ``orbit_failed``, ``below_min_elevation``,
``in_earth_shadow``, ``render_failed`` (penumbra epochs are kept: the model dims them).

**Albedo.** ``albedo_j = scale_j x rho_j``, with ``rho_j`` the scenario's own reflectance of
the target in band j: each part's material reflectance (``reflectance``; for ``plastic`` its
``diffuse_reflectance``; Fresnel reflectances at normal incidence) averaged over the parts
weighted by their surface area, then averaged over the band with the photon weights of the
reference paper's eq. 3 (band response x optics x QE x wavelength:
:func:`speclight.estimate.upsampling.band_albedo`). For a constant reflectance r it is
``r x scale``. With several materials one scale per band multiplies all of them: the albedo
is then the area-weighted mean, a summary rather than a per-material value.
"""

from __future__ import annotations

import math
import sys
import warnings
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight import schema
from speclight.errors import InputError
from speclight.estimate.fit import F64, fit_scales, shot_noise_sigma
from speclight.estimate.measured import MeasuredLightCurve, bin_light_curve
from speclight.estimate.roughness_fit import PROFILE_SIGMAS, fit_roughness
from speclight.estimate.upsampling import band_albedo
from speclight.scenario import LoadedScenario
from speclight.scenario.overrides import replace_fields

FREE_CHOICES = ("albedo", "roughness")
ROUGH_BSDFS = ("beckmann", "ggx", "plastic")
ROUGHNESS_BOUNDS = (0.01, 1.0)
_SKIP = (
    schema.FLAG_ORBIT_FAILED
    | schema.FLAG_BELOW_MIN_ELEVATION
    | schema.FLAG_IN_SHADOW
    | schema.FLAG_RENDER_FAILED
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


def parse_free(text: str) -> tuple[str, ...]:
    """``--free albedo,roughness`` -> the parameter names, checked."""
    names = tuple(p.strip() for p in text.split(",") if p.strip())
    bad = [p for p in names if p not in FREE_CHOICES]
    if bad or not names:
        raise InputError(
            f"--free = {text!r}: give a comma-separated list of {', '.join(FREE_CHOICES)}",
            field="--free",
        )
    return names


def rough_materials(loaded: LoadedScenario) -> list[str]:
    """Names of the scenario's materials with a microfacet roughness."""
    target = loaded.scenario.target
    if target is None:
        return []
    return [n for n, m in target.materials.items() if m.bsdf in ROUGH_BSDFS and m.roughness]


def _with_roughness(loaded: LoadedScenario, values: dict[str, float]) -> LoadedScenario:
    return replace_fields(
        loaded, {f"target.materials.{name}.roughness": float(v) for name, v in values.items()}
    )


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
        Average the measurements into bins of this many seconds first
        (:func:`~speclight.estimate.bin_light_curve`); the model is evaluated at each bin's
        mean epoch, and bins holding a flagged or penumbra epoch are left out.
    progress
        Show render progress and the roughness iterations on a terminal.
    """
    from speclight.simulate import simulate

    for p in free:
        parse_free(p)
    sc = loaded.scenario
    if sc.target is None:
        raise InputError("the scenario has no target to fit", field="target")
    names = [b.name for b in sc.instrument.bands]
    if not names:
        raise InputError("the scenario has no instrument bands to fit", field="instrument.bands")
    lc = measured.select_bands(names)
    if bin_s is not None:
        lc = _binned(loaded, lc, bin_s)
    rough = rough_materials(loaded) if "roughness" in free else []
    if "roughness" in free and not rough:
        raise InputError(
            "--free roughness: the scenario has no material with a roughness "
            f"(bsdf {', '.join(ROUGH_BSDFS)})",
            field="--free",
        )
    base = _for_fitting(loaded)
    show = progress and sys.stderr.isatty()
    first = simulate(base, progress=show, time_utc=lc.time_utc)
    ds = first.dataset
    sigma = lc.sigma_per_s
    shot = shot_noise_sigma(lc.rate_per_s, sc.instrument.exposure_s, lc.n_samples)
    sigma = shot if sigma is None else np.where(np.isfinite(sigma), sigma, shot)
    usable = (ds["flags"].values.astype(np.int64) & _SKIP) == 0
    m = np.where(usable[:, None], lc.rate_per_s, np.nan)
    rho = _band_reflectance(loaded, ds)
    notes: list[str] = []
    if rough:
        fit = _fit_rough(base, first, m, sigma, rough, "albedo" in free, show)
        model, scales = fit.model, fit.scales
        roughness = {
            n: (float(v), float(s))
            for n, v, s in zip(rough, fit.roughness, fit.roughness_std, strict=True)
        }
        method = "SLSQP over roughness (variable projection), weighted least squares for scales"
        notes += _roughness_problems(rough, fit)
        extra = {"n_simulations": fit.n_simulations, "n_iterations": fit.n_iterations}
    else:
        model = ds["count_rate"].transpose("time", "band").values.astype(float)
        model = np.where(usable[:, None], model, np.nan)
        if "albedo" not in free:
            raise InputError("--free must include albedo or roughness", field="--free")
        scales = fit_scales(model, m, sigma)
        roughness, method, extra = {}, "weighted least squares (closed form; linear in albedo)", {}
    notes += _scale_problems(names, scales.scale, scales.scale_std, scales.n_used)
    fitted = model * scales.scale[None, :]
    return _result(lc, names, rho, scales, roughness, m, fitted, method, notes, extra)


def _fit_rough(
    base: LoadedScenario,
    first: Any,
    m: F64,
    sigma: F64,
    rough: list[str],
    fit_scale: bool,
    show: bool,
) -> Any:
    from speclight.simulate import simulate

    usable: NDArray[np.bool_] = np.asarray(np.isfinite(m).any(axis=1))
    target = base.scenario.target
    assert target is not None
    start = np.array([float(target.materials[n].roughness or 0.0) for n in rough])

    def model(alpha: F64) -> F64:
        run = simulate(
            _with_roughness(base, dict(zip(rough, alpha, strict=True))),
            progress=show,
            geometry=first.geometry,
        )
        c = run.dataset["count_rate"].transpose("time", "band").values.astype(float)
        return np.where(usable[:, None], c, np.nan)

    on_iteration = None
    if show:
        from rich.console import Console

        console = Console(stderr=True)

        def on_iteration(k: int, alpha: F64, chi2: float) -> None:
            values = ", ".join(f"{n}={a:.4f}" for n, a in zip(rough, alpha, strict=True))
            console.print(f"fit iteration {k}: roughness {values}, chi2 {chi2:.6g}")

    c0 = first.dataset["count_rate"].transpose("time", "band").values.astype(float)
    return fit_roughness(
        model,
        m,
        sigma,
        start,
        ROUGHNESS_BOUNDS,
        fit_scale=fit_scale,
        on_iteration=on_iteration,
        start_model=np.where(usable[:, None], c0, np.nan),
    )


def _roughness_problems(rough: list[str], fit: Any) -> list[str]:
    out = []
    span = ROUGHNESS_BOUNDS[1] - ROUGHNESS_BOUNDS[0]
    if fit.flat:
        return [f"roughness of material '{rough[0]}' is not constrained by the data: {fit.flat}"]
    if not fit.success:
        out.append(f"SLSQP did not converge: {fit.message}")
    for k, name in enumerate(rough):
        value, std = fit.roughness[k], fit.roughness_std[k]
        if fit.derivative[k] == 0 or not np.isfinite(std) or std > span:
            out.append(
                f"roughness of material '{name}' is not constrained by the data "
                f"(std {std:.3g} for bounds {ROUGHNESS_BOUNDS}: changing it changes the "
                "light curve not at all or only in brightness, which the albedo absorbs)"
            )
        elif min(value - ROUGHNESS_BOUNDS[0], ROUGHNESS_BOUNDS[1] - value) < 1e-6:
            out.append(f"roughness of material '{name}' stopped at a bound ({value:g})")
        elif np.nanmin(fit.profile[k]) < 1.0:
            side = "below" if fit.profile[k, 0] < fit.profile[k, 1] else "above"
            out.append(
                f"roughness of material '{name}' is not at a well-defined minimum: chi2 "
                f"{'falls' if np.nanmin(fit.profile[k]) < 0 else 'barely rises'} "
                f"{PROFILE_SIGMAS:g} std {side} {value:.4g} (the data may bound it only on "
                "one side)"
            )
    return out


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


def _binned(loaded: LoadedScenario, lc: MeasuredLightCurve, bin_s: float) -> MeasuredLightCurve:
    """``lc`` averaged into ``bin_s`` bins, without the bins that hold an epoch the model
    cannot represent by one epoch: flagged (shadow, below the horizon...) or in penumbra, where
    the light changes too fast for the bin's mean epoch to stand for it."""
    from speclight.simulate.geometry_stage import scenario_geometry

    binned = bin_light_curve(lc, bin_s)
    flags = scenario_geometry(loaded, lc.time_utc).flags.astype(np.int64)
    bad = ((flags & (_SKIP | schema.FLAG_PENUMBRA)) != 0).astype(float)[:, None]
    marker = replace(lc, band_names=["flagged"], rate_per_s=bad, sigma_per_s=None)
    keep = bin_light_curve(marker, bin_s).rate_per_s[:, 0] == 0
    rate = np.where(keep[:, None], binned.rate_per_s, np.nan)
    return replace(binned, rate_per_s=rate)


def _band_reflectance(loaded: LoadedScenario, ds: Any) -> F64:
    """The scenario's target reflectance per band (module doc: Albedo) [1] (B,)."""
    from speclight.simulate.reflection import build_target

    target = build_target(loaded)
    wl = ds["wavelength"].values.astype(float)
    spectrum, total = np.zeros(wl.size), 0.0
    for part in target.parts:
        mat = part.material
        refl = mat.diffuse_reflectance if mat.bsdf == "plastic" else mat.reflectance
        assert refl is not None
        spectrum += part.area_m2 * refl.evaluate(wl)
        total += part.area_m2
    response = (
        ds["band_response"].transpose("band", "wavelength").values
        * ds["optics_transmission"].values[None, :]
        * ds["detector_qe"].transpose("band", "wavelength").values
    )
    return band_albedo(spectrum / total, response, wl)


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


__all__ = ["FREE_CHOICES", "FitResult", "fit_scenario", "parse_free", "rough_materials"]
