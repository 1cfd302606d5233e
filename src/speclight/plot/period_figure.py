"""Figure of ``speclight period``: the periodogram and the phase-folded light curves.

Top: the multi-band power against trial period (log axis), the candidates numbered, the
power of a 1 % false-alarm probability (bootstrap, Gumbel fit) dashed, the photometric and
rotation periods marked. Bottom: each band's detrended magnitude folded at the rotation
period (synodic: as the light curve shows it), offset band by band, with the fitted harmonic
model, so the two halves of a two-fold symmetric body can be compared by eye.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from speclight.estimate.period.period_run import PeriodResult
from speclight.estimate.period.periodogram import design_matrix, harmonic_chi2
from speclight.plot.style import new_figure

#: Magnitude offset between bands in the folded panel, in units of the largest band's
#: 5-95 percentile range.
OFFSET_SPREAD = 1.2


def period_figure(result: PeriodResult) -> Any:
    """Periodogram (top) and folded light curves (bottom) of a period result.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib import colormaps

    fig = new_figure(9.0, 7.0)
    ax1, ax2 = fig.subplots(2, 1, gridspec_kw={"height_ratios": [1, 1.4]})
    period = 1.0 / result.frequency_hz
    ax1.plot(period, result.power, lw=0.8, color="k")
    ax1.set_xscale("log")
    level = result.bootstrap.power_at(0.01)
    ax1.axhline(level, ls="--", color="tab:red", lw=0.8, label="1 % false-alarm level")
    for i, (p, w) in enumerate(result.candidates, 1):
        ax1.annotate(str(i), (p, w), textcoords="offset points", xytext=(0, 3), ha="center")
    dec = result.decision
    ax1.axvline(dec.photometric_period_s, color="tab:blue", lw=0.8, label="photometric period")
    ax1.axvline(dec.rotation_period_s, color="tab:green", lw=1.2, ls=":", label="rotation period")
    ax1.set_xlabel("trial period [s]")
    ax1.set_ylabel("power (fraction of chi2 explained)")
    ax1.legend(loc="upper left", fontsize="small")
    ax1.set_title(f"rotation period {result.period_s:.5g} s", fontsize="medium")

    s = result.series
    p_rot = dec.rotation_period_s
    orders = list(range(1, 2 * result.harmonics + 1))
    _, _, coefs = harmonic_chi2(s, 1.0 / p_rot, orders)
    spread = max(
        float(np.subtract(*np.percentile(s.y[s.band == b], [95, 5])))
        for b in range(s.n_bands)
        if np.any(s.band == b)
    )
    cmap = colormaps["viridis"]
    phase_grid = np.linspace(0.0, 1.0, 200)
    for b in range(s.n_bands):
        m = s.band == b
        if not np.any(m):
            continue
        colour = cmap(b / max(s.n_bands - 1, 1))
        off = b * OFFSET_SPREAD * spread
        phase = (s.t_s[m] / p_rot) % 1.0
        ax2.plot(phase, s.y[m] + off, ".", ms=2, color=colour, label=result.band_names[b])
        model = design_matrix(phase_grid * p_rot, 1.0 / p_rot, orders) @ coefs[b]
        ax2.plot(phase_grid, model + off, "-", lw=0.8, color="k")
    ax2.invert_yaxis()
    ax2.axvline(0.5, color="0.6", lw=0.6)
    ax2.set_xlabel(f"rotation phase (fold at {p_rot:.5g} s)")
    ax2.set_ylabel("detrended magnitude + offset [mag]")
    ax2.legend(loc="upper right", fontsize="x-small", ncol=2, markerscale=4)
    return fig
