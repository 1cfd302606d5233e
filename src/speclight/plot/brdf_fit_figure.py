"""Figure of ``speclight brdf-fit``: the fitted model drawn over the measured table.

Top: the table's in-plane samples (dots, one colour per incidence angle) and the model along
the same plane (lines), BRDF on a log axis against the signed exitance angle (positive on
the specular side); each incidence's RMS residual in the legend. Bottom: the residual
``log10 f_model - log10 f_measured`` of every sample.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from speclight.plot.style import new_figure
from speclight.target.brdf_fit.form_coefficients import evaluate
from speclight.target.brdf_fit.log_fit import LOG_FLOOR, BrdfFit
from speclight.target.brdf_samples import TableSamples

#: Exitance angles of the model lines [deg] (fine enough for a 1 deg wide peak).
LINE_DEG = np.linspace(-89.5, 89.5, 1433)


def _in_plane(theta_i_deg: float, theta_o_deg: Any) -> TableSamples:
    to = np.asarray(theta_o_deg, dtype=float)
    ones = np.ones_like(to)
    return TableSamples(theta_i_deg * ones, to, ones, float("nan"), "")


def brdf_fit_figure(samples: TableSamples, fit: BrdfFit) -> Any:
    """The figure (a matplotlib ``Figure``) of a fit to a table."""
    from matplotlib import colormaps

    fig = new_figure(6.5)
    ax, ax_r = fig.subplots(2, 1, sharex=True, height_ratios=(3, 1.3))
    keep = samples.usable() & (samples.brdf > fit.min_brdf)
    model = evaluate(fit.model, fit.coefficients, *samples.cosines())
    residual = np.log10(np.maximum(model, LOG_FLOOR)) - np.log10(np.where(keep, samples.brdf, 1.0))
    for k, (t, rms) in enumerate(zip(fit.incidence_deg, fit.rms_dex, strict=True)):
        colour = colormaps["viridis"](k / max(len(fit.incidence_deg) - 1, 1) * 0.9)
        on = keep & (samples.theta_i_deg == t)
        label = f"incidence {t:g} deg: RMS {rms:.2f} dex"
        ax.semilogy(samples.theta_o_deg[on], samples.brdf[on], ".", ms=3, color=colour, label=label)
        line = _in_plane(float(t), LINE_DEG)
        ax.semilogy(LINE_DEG, evaluate(fit.model, fit.coefficients, *line.cosines()), "-",
                    lw=1.0, color=colour)  # fmt: skip
        ax_r.plot(samples.theta_o_deg[on], residual[on], ".", ms=3, color=colour)
    ax.set_ylabel("BRDF [sr-1]")
    ax.legend(fontsize="small", frameon=False)
    held = ", albedo held at most 1" if fit.constrained else ""
    ax.set_title(
        f"{fit.model} fitted to {fit.source} (lines; dots: the table): RMS "
        f"{fit.rms_dex_all:.2f} dex, largest albedo {fit.albedo:.2f}{held}",
        fontsize="medium",
    )
    ax_r.axhline(0.0, color="0.5", lw=0.8)
    ax_r.set_ylabel("model - table [dex]")
    ax_r.set_xlabel("exitance angle in the plane of incidence [deg] (+: specular side)")
    return fig
