"""The roughness part of ``speclight fit`` (:func:`speclight.estimate.fit_scenario`).

Glue between the scenario and the two plain-array fits: :func:`fit_rough_slsqp` simulates
the scenario for every roughness value SLSQP tries (:mod:`.roughness_fit`);
:func:`fit_rough_gradient` evaluates the count rates and their analytic derivatives
(:mod:`.roughness_gradient`) for the trust-region fit (:mod:`.gradient_fit`);
:func:`roughness_problems` says what the fit cannot claim.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.fitting.fit import F64
from speclight.estimate.fitting.fit_bins import EpochBins
from speclight.estimate.fitting.fit_quality import CLIP_SIGMA
from speclight.estimate.fitting.noise_model import PoissonNoise
from speclight.estimate.fitting.roughness_fit import fit_roughness
from speclight.estimate.fitting.roughness_uncertainty import unconstrained_text
from speclight.scenario import LoadedScenario
from speclight.scenario.overrides import replace_fields

ROUGHNESS_BOUNDS = (0.01, 1.0)


def _with_roughness(loaded: LoadedScenario, values: dict[str, float]) -> LoadedScenario:
    return replace_fields(
        loaded, {f"target.materials.{name}.roughness": float(v) for name, v in values.items()}
    )


def fit_rough_slsqp(
    base: LoadedScenario,
    first: Any,
    *,
    m: F64,
    sigma: PoissonNoise,
    rough: list[str],
    fit_scale: bool,
    show: bool,
    scan: bool = True,
    bins: EpochBins | None = None,
    clip_sigma: float | None = CLIP_SIGMA,
) -> Any:
    """SLSQP over the roughness (:mod:`.roughness_fit`), the scenario simulated at the
    measured epochs for every roughness value tried.

    Parameters
    ----------
    base
        The scenario to fit (its roughness values are the start).
    first
        The simulation of ``base`` at the measured epochs (its geometry is reused).
    m
        Measured count rates (N, B) [s-1]; NaN: not used.
    sigma
        Their noise (:class:`.noise_model.PoissonNoise`, with the data's own sigmas where
        given).
    rough
        Names of the materials whose roughness is fitted.
    fit_scale
        Fit a scale per band too (``free`` includes ``albedo``).
    show
        Print the iterations on a terminal.
    scan
        Scan the bounds before the local method (:mod:`.roughness_scan`).
    bins
        Rates, model and measurements averaged over these bins (:mod:`.fit_bins`), or None.
    clip_sigma
        Leave out measurements this many robust sigmas from the fit (:mod:`.fit_quality`).
    """
    from speclight.simulation import simulate

    usable, start = _usable_and_start(base, m, rough)

    def per_epoch(alpha: F64) -> F64:
        run = simulate(
            _with_roughness(base, dict(zip(rough, alpha, strict=True))),
            progress=show,
            geometry=first.geometry,
        )
        c = run.dataset["count_rate"].transpose("time", "band").values.astype(float)
        return np.where(usable[:, None], c, np.nan)

    def model(alpha: F64) -> F64:
        return per_epoch(alpha) if bins is None else bins.mean(per_epoch(alpha))

    on_iteration = _printer(rough, "iteration") if show else None
    c0 = first.dataset["count_rate"].transpose("time", "band").values.astype(float)
    c0 = np.where(usable[:, None], c0, np.nan)
    m_fit, s_fit = (m, sigma) if bins is None else (bins.mean(m), sigma.binned(bins))
    return fit_roughness(
        model,
        m_fit,
        s_fit,
        start,
        ROUGHNESS_BOUNDS,
        fit_scale=fit_scale,
        on_iteration=on_iteration,
        start_model=c0 if bins is None else bins.mean(c0),
        scan=scan,
        clip_sigma=clip_sigma,
    )


def fit_rough_gradient(
    base: LoadedScenario,
    first: Any,
    *,
    m: F64,
    sigma: PoissonNoise,
    rough: list[str],
    fit_scale: bool,
    show: bool,
    scan: bool = True,
    bins: EpochBins | None = None,
    clip_sigma: float | None = CLIP_SIGMA,
) -> Any:
    """The trust-region fit with analytic derivatives (:mod:`.gradient_fit`).

    Parameters
    ----------
    base
        The scenario to fit (its roughness values are the start).
    first
        The simulation of ``base`` at the measured epochs (its geometry is reused).
    m
        Measured count rates (N, B) [s-1]; NaN: not used.
    sigma
        Their noise (:class:`.noise_model.PoissonNoise`, with the data's own sigmas where
        given).
    rough
        Names of the materials whose roughness is fitted.
    fit_scale
        Fit a scale per band too (``free`` includes ``albedo``).
    show
        Print the iterations on a terminal.
    scan
        Scan the bounds before the local method (:mod:`.roughness_scan`).
    bins
        Rates, derivatives and measurements averaged over these bins, or None.
    clip_sigma
        Leave out measurements this many robust sigmas from the fit (:mod:`.fit_quality`).
    """
    from speclight.estimate.fitting.gradient_fit import fit_roughness_gradient
    from speclight.estimate.fitting.roughness_gradient import RoughnessRates

    usable, start = _usable_and_start(base, m, rough)
    rates = RoughnessRates(base, first.geometry, rough, usable)

    def binned(alpha: F64) -> tuple[F64, F64]:
        c, dc = rates(alpha)
        assert bins is not None
        return bins.mean(c), bins.mean(dc, axis=1)

    m_fit, s_fit = (m, sigma) if bins is None else (bins.mean(m), sigma.binned(bins))
    return fit_roughness_gradient(
        rates if bins is None else binned, m_fit, s_fit, start, ROUGHNESS_BOUNDS,
        fit_scale=fit_scale, on_iteration=_printer(rough, "evaluation") if show else None,
        scan=scan, clip_sigma=clip_sigma,
    )  # fmt: skip


def _usable_and_start(
    base: LoadedScenario, m: F64, rough: list[str]
) -> tuple[NDArray[np.bool_], F64]:
    """Epochs with any measurement (N,), and the scenario's roughness of ``rough`` (K,)."""
    usable: NDArray[np.bool_] = np.asarray(np.isfinite(m).any(axis=1))
    target = base.scenario.target
    assert target is not None
    return usable, np.array([float(target.materials[n].roughness or 0.0) for n in rough])


def _printer(rough: list[str], step: str) -> Any:
    """A progress line per fit ``step`` ("iteration", "evaluation") on stderr."""
    from rich.console import Console

    console = Console(stderr=True)

    def on_iteration(k: int, alpha: F64, chi2: float) -> None:
        values = ", ".join(f"{n}={a:.4f}" for n, a in zip(rough, alpha, strict=True))
        console.print(f"fit {step} {k}: roughness {values}, chi2 {chi2:.6g}")

    return on_iteration


def roughness_problems(rough: list[str], fit: Any) -> list[str]:
    """What the roughness fit cannot claim, one line per problem (empty: nothing)."""
    out = []
    if not fit.success:
        out.append(f"the roughness fit did not converge: {fit.message}")
    lo, hi = ROUGHNESS_BOUNDS
    for k, name in enumerate(rough):
        if fit.unconstrained[k]:
            text = unconstrained_text(fit.unconstrained[k], fit.ranges[k], lo, hi)
            out.append(f"roughness of material '{name}' is not constrained by the data: {text}")
    return out


__all__ = ["ROUGHNESS_BOUNDS", "fit_rough_gradient", "fit_rough_slsqp", "roughness_problems"]
