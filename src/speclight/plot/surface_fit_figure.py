"""Figure of ``speclight fit --free brdf``: residuals (observed - model) against phase angle
at the start and fitted, the cross-validated residuals, and the yaw profile where the yaw
was fitted."""

from __future__ import annotations

from typing import Any

import numpy as np

from speclight.plot.style import new_figure


def surface_fit_figure(result: Any) -> Any:
    """The figure of a :class:`~speclight.estimate.surface_fit.SurfaceFitResult`."""
    profile = result.yaw_profile
    fig = new_figure(4.5, 11.0 if profile else 7.0)
    axes = fig.subplots(1, 2 if profile else 1, squeeze=False)[0]
    ax = axes[0]
    phase = result.phase_angle_deg
    s = result.summary
    ax.plot(phase, result.residual_start_mag, "o", ms=3, color="0.6",
            label=f"start (RMS {s['start']['rms_mag']:.3f} mag)")  # fmt: skip
    cv = s["cross_validation"]["rms_mag"]
    cv_label = "cross-validated" + (f" (RMS {cv:.3f} mag)" if cv is not None else "")
    ax.plot(phase, result.residual_cross_mag, "^", ms=3, mfc="none", color="tab:orange",
            label=cv_label)  # fmt: skip
    ax.plot(phase, result.residual_fit_mag, "o", ms=3, color="tab:blue",
            label=f"fitted (RMS {s['fit']['rms_mag']:.3f} mag)")  # fmt: skip
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xlabel("phase angle [deg]")
    ax.set_ylabel("observed - model [mag]")
    ax.legend(fontsize=8)
    ax.set_title(f"{s['n_used']} observations")
    if profile:
        yaw = np.array([p[0] for p in profile])
        chi2 = np.array([p[1] for p in profile])
        axes[1].plot(yaw, chi2, "o-")
        axes[1].set_xlabel("yaw offset [deg]")
        axes[1].set_ylabel("chi-square (BRDFs fitted at each yaw)")
    return fig
