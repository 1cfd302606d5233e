"""Figure of ``speclight fit``: measured and fitted count rates, and band signal ratios.

The layout of the reference paper's Figures 9 and 10 (Nussbaum et al. 2022, "Spectral
Light Curve Simulation for Parameter Estimation from Space Debris"): above, the count rate
of each band, measured (solid) and fitted (dashed); below, the ratio of each band's rate to
the rate of a reference band (the band with the largest summed measured signal), measured
and fitted, at the epochs where the reference band is above :data:`FAINT` of its peak.

With ``--free brdf`` (:func:`surface_fit_figure`): residuals (observed - model) against phase
angle at the start, fitted and cross-validated, and the yaw profile where the yaw was fitted.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.plot.style import new_figure, set_time_ticks

F64 = NDArray[np.float64]
#: Band ratios are drawn where the reference band's fitted rate is at least this fraction of
#: its peak (fainter epochs' measured ratios are noise over noise) [1].
FAINT = 0.05


def fit_figure(
    time_utc: NDArray[np.datetime64], measured_per_s: F64, fitted_per_s: F64, band_names: list[str]
) -> Any:
    """The figure (a matplotlib ``Figure``) of one fit.

    Parameters
    ----------
    time_utc
        (N,) epochs, UTC.
    measured_per_s, fitted_per_s
        (N, B) measured and fitted count rates [s-1], NaN where not used.
    band_names
        (B,) band names.
    """
    from matplotlib import colormaps

    fig = new_figure(7.0)
    top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=[3, 2])
    t = np.asarray(time_utc, dtype="datetime64[ns]")
    m = np.asarray(measured_per_s, dtype=float)
    f = np.asarray(fitted_per_s, dtype=float)
    colours = [colormaps["tab10"](j % 10) for j in range(len(band_names))]
    for j, name in enumerate(band_names):
        top.plot(t, m[:, j], "-", color=colours[j], lw=1.0, label=f"{name}")
        top.plot(t, f[:, j], "--", color=colours[j], lw=1.2)
    top.set_ylabel("count rate [s$^{-1}$]")
    top.set_title("measured (solid) and fitted (dashed) count rates")
    top.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small", frameon=False)
    ref = int(np.nanargmax(np.nansum(m, axis=0))) if np.any(np.isfinite(m)) else 0
    # ratios of faint epochs are noise over noise: drawn only where the reference band's
    # fitted rate reaches FAINT of its peak
    peak = np.nanmax(f[:, ref]) if np.any(np.isfinite(f[:, ref])) else np.nan
    bright = f[:, ref] >= FAINT * peak
    m = np.where(bright[:, None], m, np.nan)
    f = np.where(bright[:, None], f, np.nan)
    with np.errstate(divide="ignore", invalid="ignore"):
        for j, name in enumerate(band_names):
            if j == ref:
                continue
            bottom.plot(t, m[:, j] / m[:, ref], "-", color=colours[j], lw=0.8,
                        label=f"{name}/{band_names[ref]}")  # fmt: skip
            bottom.plot(t, f[:, j] / f[:, ref], "--", color=colours[j], lw=1.2)
    bottom.set_ylabel(f"ratio to {band_names[ref]}")
    bottom.set_title(
        "signal ratios between bands, measured (solid) and fitted (dashed), where the "
        f"reference band is above {FAINT:.0%} of its peak",
        fontsize="medium",
    )
    if len(band_names) > 1:
        bottom.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small",
                      frameon=False)  # fmt: skip
        with np.errstate(divide="ignore", invalid="ignore"):
            ratios = np.delete(f, ref, axis=1) / f[:, [ref]]
        finite = ratios[np.isfinite(ratios)]
        if finite.size:  # the measured ratios of faint epochs can be wild: frame the model's
            lo, hi = np.percentile(finite, [0.5, 99.5])
            pad = 0.25 * (hi - lo) + 0.05 * abs(hi)
            bottom.set_ylim(lo - pad, hi + pad)
    set_time_ticks(bottom)
    day = np.datetime_as_string(t[0], unit="D") if t.size else ""
    bottom.set_xlabel(f"time [UTC] on {day}")
    return fig


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
