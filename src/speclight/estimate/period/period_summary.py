"""PERIOD.json's keys from a :class:`.period_result.PeriodResult` (docs/period.md)."""

from __future__ import annotations

from typing import Any

from speclight.estimate.period.period_decision import ALPHA

#: A :class:`.period_result.PeriodResult` (not imported: that module imports this one).
PeriodResult = Any


def _fap_method(r: PeriodResult) -> str:
    a = r.analytic
    level = (
        f"the peak's power divided by the noise level beside it, {a.noise_level:.3g} times "
        "the white level (the detrended data's Lomb-Scargle power 1.5-10 peak widths from "
        "each harmonic over its mean; 1 for white residuals)"
    )
    if r.bootstrap is None:
        return (
            f"FAP analytic (Baluev 2008 for nu = {a.dof_signal} parameters of the harmonics, "
            f"N = {a.n_points} points, {a.n_bands} band(s)) of {level}"
        )
    return (
        f"FAP from a Gumbel law fitted to the maximum powers of {r.bootstrap.draws} "
        f"permutation draws (seed {r.bootstrap.seed}; the (value, sigma) pairs shuffled "
        f"among the epochs of each band, same grid; Suveges 2014) at {level}"
    )


def _tumbling(r: PeriodResult) -> dict[str, Any] | None:
    t = r.tumbling
    if t is None:
        return None
    return {
        "detected": t.detected,
        "periods_s": [1.0 / f for f in t.frequencies_hz],
        "second_false_alarm_probability": t.second_fap,
        "f_statistic": t.f_statistic,
        "p_value": t.p_value,
        "combinations": t.combinations,
        "text": t.text,
    }


def _outliers(r: PeriodResult) -> list[dict[str, Any]]:
    o = r.outliers
    if o is None:
        return []
    return [
        {"time_s": float(t), "band": r.band_names[int(b)], "residual_sigma": float(s)}
        for t, b, s in zip(o.t_s, o.band, o.residual_sigma, strict=True)
    ]


def summary(r: PeriodResult) -> dict[str, Any]:
    """PERIOD.json as a dict (NaN where undetermined)."""
    syn = r.synodic
    boot = r.bootstrap
    perm, upper = (
        boot.permutation_p_value(r.best_power / r.analytic.noise_level) if boot else (None, None)
    )
    return {
        "period_s": r.period_s,
        "period_std_s": r.period_std_s,
        "detected": r.detected,
        "verdict": r.verdict(),
        "period_lower_bound_s": r.period_lower_bound_s,
        "best_candidate_period_s": r.decision.rotation_period_s,
        "false_alarm_probability": r.false_alarm_probability,
        "false_alarm_method": "bootstrap" if boot is not None else "analytic",
        "noise_level": r.analytic.noise_level,
        "permutation_p_value": perm,
        "permutation_p_value_is_upper_bound": upper,
        "method": (
            "multi-band Lomb-Scargle (astropy LombScargle per band, nterms = "
            f"{r.harmonics}, chi2-weighted sum; VanderPlas & Ivezic 2015) on magnitudes "
            f"detrended per band and pass; {_fap_method(r)}; period_std_s from the "
            "curvature of chi2(f) at its minimum (the harmonics and the trend per band the "
            "light curve needs, F-tests: refined_harmonics, refined_trend_degree, "
            "refined_amplitude_change), "
            "delta chi2 = 1 after scaling by the reduced chi2, times the coloured-noise "
            "factor sqrt(sum w_k / sum (w_k / R_k)) (Kay 1993 ch. 3; never below 1), and "
            "where the synodic correction is not applied the synodic term bound/sqrt(3) in "
            f"quadrature; residuals' lag-1 correlation rho = {r.peak.residual_correlation:.3f}"
        ),
        "refined_harmonics": list(r.peak.orders),
        "refined_trend_degree": r.peak.trend_degree,
        "refined_amplitude_change": r.peak.amplitude_change,
        "candidates": [{"period_s": p, "power": w} for p, w in r.candidates],
        "photometric_period_s": r.decision.photometric_period_s,
        "synodic_period_s": r.decision.rotation_period_s,
        "period_statistical_std_s": r.statistical_std_s,
        "search_edge": (
            None
            if r.edge is None or not r.detected
            else {"side": r.edge.side, "bound_s": r.edge.bound_s, "text": r.edge.text}
        ),
        "period_synodic_std_s": r.synodic_std_s,
        "decision": r.decision.decision,
        "halves_tests": [
            {
                "fold_period_s": t.period_s,
                "f_statistic": t.f_statistic,
                "p_value": t.p_value,
                "halves_differ": t.differ,
            }
            for t in r.decision.tests
        ],
        "alpha": ALPHA,
        "tumbling": _tumbling(r),
        "outliers": _outliers(r),
        "outlier_limit_sigma": None if r.outliers is None else r.outliers.limit_sigma,
        "notices": list(r.notices),
        "synodic_correction_s": None if syn is None else syn.correction_s,
        "synodic_bound_s": None if syn is None else syn.bound_s,
        "synodic_linear_period_s": None if syn is None else syn.linear_period_s,
        "bisector_fit_period_s": None if syn is None else syn.bisector_fit_period_s,
        "bisector_rate_rad_s": None if syn is None else syn.bisector_rate_rad_s,
        "synodic_method": (
            "geometry unknown (a CSV without --scenario): no correction"
            if syn is None
            else syn.method
        ),
        "best_power": r.best_power,
        "power_at_fap_1_percent": r.power_at(0.01),
        "harmonics": r.harmonics,
        "frequency_grid_hz": {
            "min": float(r.frequency_hz[0]),
            "max": float(r.frequency_hz[-1]),
            "n": int(r.frequency_hz.size),
        },
        "n_epochs": r.n_epochs,
        "bands": r.band_names,
        "source": r.source,
    }


__all__ = ["summary"]
