"""Figure of ``speclight upsample``: the spectrum, the band albedos and the band curves.

Like the reference paper's Figures 11-12 (Nussbaum et al. 2022): the upsampled reflectance
against wavelength, each band's albedo as a point at the band's photon-weighted centre with a
horizontal bar over its photon-weighted width (twice the standard deviation), and below,
the band responses (band curve x optics x QE) that weight the spectrum.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from speclight.estimate.spectra.upsample_run import ScenarioSpectrum
from speclight.plot.style import new_figure


def _band_colours(centre_nm: np.ndarray) -> list[Any]:
    from matplotlib import colormaps

    cmap = colormaps["turbo"]
    return [cmap(float(np.clip((c - 380.0) / 720.0, 0.0, 1.0)) * 0.9 + 0.05) for c in centre_nm]


def upsample_figure(result: ScenarioSpectrum, title: str = "") -> Any:
    """The spectrum with band albedos (top) and the band responses (bottom).

    Parameters
    ----------
    result
        The upsampled spectrum and the bands it went through.
    title
        Figure title (e.g. the scenario's name).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig = new_figure(6.0, 9.0)
    top, bottom = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [2.2, 1.0]})
    s = result.spectrum
    bands = result.bands
    centre, width = result.band_centre_nm, result.band_width_nm
    colours = _band_colours(centre)
    top.plot(s.wavelength_nm, s.reflectance, color="k", lw=1.6, label="upsampled spectrum")
    for j, name in enumerate(bands.band_names):
        top.errorbar(
            centre[j],
            s.albedo[j],
            xerr=width[j] / 2,
            fmt="o",
            color=colours[j],
            ms=6,
            capsize=3,
            label=f"{name}: {s.albedo[j]:.3f}",
        )
        top.plot(centre[j], s.albedo_fit[j], "x", color="k", ms=6, mew=1.5, zorder=10)
    top.plot([], [], "x", color="k", label="band averages of the spectrum")
    state = "" if s.converged else " (fit NOT converged)"
    top.set_title(
        f"{title + ': ' if title else ''}spectrum from {len(bands.band_names)} band albedos{state}",
        loc="left",
        fontsize="medium",
    )
    top.set_ylabel("reflectance [1]")
    hi = max(1.0, float(np.nanmax(s.reflectance)) * 1.05)
    top.set_ylim(0.0, hi)
    top.grid(alpha=0.3)
    top.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small", frameon=False)
    peak = bands.response.max(axis=1, keepdims=True)
    norm = bands.response / np.where(peak > 0, peak, 1.0)
    for j, name in enumerate(bands.band_names):
        bottom.plot(bands.wavelength_nm, norm[j], color=colours[j], lw=1.2, label=name)
        bottom.fill_between(bands.wavelength_nm, norm[j], color=colours[j], alpha=0.12)
    bottom.set_ylabel("band response\n(peak = 1)")
    bottom.set_xlabel("wavelength [nm]")
    bottom.set_ylim(0.0, 1.05)
    bottom.set_xlim(bands.wavelength_nm[0], bands.wavelength_nm[-1])
    bottom.grid(alpha=0.3)
    bottom.set_title("band curve x optics transmission x detector QE", loc="left", fontsize="small")
    return fig
