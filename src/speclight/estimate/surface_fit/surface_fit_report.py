"""SURFACES.json of ``speclight fit --free brdf`` and its lines on the terminal
(docs/surface-fit.md, "SURFACES.json")."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.comparison.compare_stats import agreement, per_object
from speclight.estimate.inputs.observations import Observations
from speclight.estimate.surface_fit.robust_fit import RobustFit
from speclight.estimate.surface_fit.surface_parameters import FreeSurface, coefficient_value

F64 = NDArray[np.float64]


def _num(x: Any) -> float | None:
    """A float, or None for NaN (JSON has no NaN)."""
    v = float(x)
    return v if np.isfinite(v) else None


def stats(observed: F64, model: F64) -> dict[str, Any]:
    """Number, mean, RMS, median absolute residual [mag] and Pearson R of the pairs."""
    a = agreement(observed, model)
    return {
        "n": int(a["n"]),
        "mean_mag": _num(a["mean"]),
        "rms_mag": _num(a["rms"]),
        "median_abs_mag": _num(a["median_abs"]),
        "pearson_r": _num(a["pearson_r"]),
    }


def fit_summary(
    obs: Observations,
    surfaces: list[FreeSurface],
    fit: RobustFit,
    jacobian_std: F64,
    bootstrap: F64,
    std: F64,
    how: list[str],
    why: list[str],
    rows: NDArray[np.intp],
    start_mag: F64,
    fit_mag: F64,
    cross: F64,
    cv: list[dict[str, Any]],
    split: str,
    yaw: tuple[float | None, float, str],
    n_bootstrap: int,
) -> dict[str, Any]:
    """The SURFACES.json mapping (docs/surface-fit.md)."""
    out_surfaces: dict[str, Any] = {}
    i = 0
    messages = []
    for s in surfaces:
        params = {}
        for c in s.free:
            u, sd = float(fit.u[i]), float(std[i])
            value = c.from_fit(u)
            params[c.name] = {
                "value": value,
                "std": _num(value * np.log(10.0) * sd if c.log10 else sd),
                "log10": c.log10,
                "std_fit_variable": _num(sd),
                "std_jacobian": _num(jacobian_std[i]),
                "std_bootstrap": _num(bootstrap[i]),
                "uncertainty": how[i],
                "start": coefficient_value(s.start, c.name),
                "constrained": why[i] == "",
            }
            if why[i]:
                messages.append(f"{s.name}.{c.name} not constrained by the data ({why[i]})")
            i += 1
        out_surfaces[s.name] = {
            "bsdf": s.bsdf,
            "parameters": params,
            "coefficients": s.coefficients(fit.u[i - len(s.free) : i]),
        }
    yaw_deg, yaw_std, yaw_message = yaw
    if yaw_message:
        messages.append(yaw_message)
    if not fit.success:
        messages.append(f"least squares: {fit.message}")
    m_obs = obs.magnitude[rows]
    cv_rms = [h["rms_mag"] for h in cv if h["rms_mag"] is not None]
    summary: dict[str, Any] = {
        "kind": "surface_fit",
        "surfaces": out_surfaces,
        "yaw_offset_deg": None
        if yaw_deg is None
        else {"value": yaw_deg, "std": _num(yaw_std), "constrained": not yaw_message},
        "n_rows": int(obs.time_utc.size),
        "n_used": int(rows.size),
        "scatter_tau_mag": fit.tau_mag,
        "chi2": fit.chi2,
        "dof": fit.dof,
        "start": stats(m_obs, start_mag[rows]),
        "fit": stats(m_obs, fit_mag[rows]),
        "cross_validation": {
            "split": split,
            "halves": cv,
            "rms_mag": _num(np.sqrt(np.mean(np.square(cv_rms)))) if cv_rms else None,
        },
        "n_bootstrap": n_bootstrap,
        "converged": not messages,
        "message": "; ".join(messages) or "ok",
    }
    if obs.object_name is not None:
        names, index = obs.object_index()
        per = per_object(m_obs, fit_mag[rows], index[rows], len(names))
        cvo = per_object(m_obs, m_obs - cross[rows], index[rows], len(names))
        summary["objects"] = {
            str(name): {
                "n": int(per["n"][j]),
                "mean_mag": _num(per["mean"][j]),
                "rms_mag": _num(per["rms"][j]),
                "pearson_r": _num(per["pearson_r"][j]),
                "cross_validated_rms_mag": _num(cvo["rms"][j]),
            }
            for j, name in enumerate(names)
        }
    return summary


def summary_lines(summary: dict[str, Any]) -> list[str]:
    """The fit on the terminal: each coefficient, the yaw, the scatter before and after and
    the cross-validated RMS."""
    lines = []
    if not summary["converged"]:
        lines.append(f"not converged: {summary['message']}")
    for name, s in summary["surfaces"].items():
        cells = []
        for p, v in s["parameters"].items():
            spread = f" +- {v['std']:.2g}" if v["constrained"] and v["std"] is not None else ""
            cells.append(
                f"{p} {v['value']:.4g}{spread}" + ("" if v["constrained"] else " (not constrained)")
            )
        lines.append(f"{name} ({s['bsdf']}): " + ", ".join(cells))
    yaw = summary["yaw_offset_deg"]
    if yaw is not None:
        spread = f" +- {yaw['std']:.2g}" if yaw["std"] is not None else " (not constrained)"
        lines.append(f"yaw offset: {yaw['value']:.3g} deg{spread}")
    st, fi, cv = summary["start"], summary["fit"], summary["cross_validation"]
    cv_text = f"{cv['rms_mag']:.3f} mag" if cv["rms_mag"] is not None else "n/a"
    lines.append(
        f"{summary['n_used']} of {summary['n_rows']} observations: RMS {st['rms_mag']:.3f} mag "
        f"at the start, {fi['rms_mag']:.3f} mag fitted (scatter beyond the sigmas "
        f"{summary['scatter_tau_mag']:.3f} mag); cross-validated RMS {cv_text} (halves by "
        f"{cv['split']})"
    )
    return lines
