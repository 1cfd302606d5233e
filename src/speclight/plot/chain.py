"""One epoch followed through the chain: Sun, reflection, atmosphere, instrument, bands."""

from __future__ import annotations

import re
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from speclight import schema as v
from speclight.constants import HC_J_M
from speclight.plot.style import band_styles, epoch_summary, flags, new_figure

#: The name ``G-<centre_nm>/<sigma_nm>`` of a Gaussian band (``instrument.bands``): the second
#: number is the standard deviation, not the FWHM, which the band panel's title says.
GAUSSIAN_NAME = re.compile(r"^G-\d+(\.\d*)?/\d+(\.\d*)?$")


def _row(ds: xr.Dataset, name: str, i: int) -> NDArray[np.float64]:
    return np.asarray(ds[name].isel(time=i).values, dtype=np.float64)


def _per_band(ds: xr.Dataset, name: str) -> NDArray[np.float64]:
    """A (band, wavelength) curve; a (wavelength,) one is repeated for every band."""
    da = ds[name]
    if "band" in da.dims:
        return np.asarray(da.transpose("band", "wavelength").values, dtype=np.float64)
    return np.broadcast_to(da.values, (ds.sizes.get("band", 1), ds.sizes["wavelength"]))


def chain_panels(ds: xr.Dataset) -> list[str]:
    """The chain steps this dataset can show, in order."""
    steps = [n for n in ("solar_irradiance", "intensity", "transmission") if n in ds]
    if "spectral_flux" in ds:
        steps.append("instrument")
        if ds.sizes.get("band", 0) and "band_response" in ds:
            steps.append("bands")
    return steps


def chain_figure(ds: xr.Dataset, epoch: int, chosen: str = "") -> Any:
    """Spectra of epoch ``epoch`` at each step of the chain, on one wavelength axis.

    Steps: solar irradiance at the target; radiant intensity toward the observer
    (with its Monte Carlo standard error); atmospheric transmission; spectral flux at
    the aperture, after the optics and after the detector QE; and each band's detected
    photo-electron spectrum :math:`\\Phi_\\lambda \\tau \\eta R_b \\lambda / (hc)`, whose
    integral is the band's count rate (the legend gives the dataset's ``count_rate``).
    """
    steps = chain_panels(ds)
    heights = {"bands": 2.6}
    ratios = [heights.get(s, 1.7) for s in steps]
    fig = new_figure(height_in=1.2 + sum(ratios))
    axes = np.atleast_1d(
        fig.subplots(len(steps), 1, sharex=True, gridspec_kw={"height_ratios": ratios})
    )
    w = ds["wavelength"].values
    for ax, step in zip(axes, steps, strict=True):
        _DRAW[step](ds, ax, w, epoch)
        ax.grid(alpha=0.3)
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small", frameon=False)
    for ax in axes[:-1]:
        ax.tick_params(labelbottom=False)
    axes[-1].set_xlabel("wavelength [nm]")
    axes[-1].set_xlim(w.min(), w.max())
    name = ds.attrs.get("scenario_name", "speclight dataset")
    why = f" ({chosen})" if chosen else ""
    status = epoch_status(ds, epoch)
    status = f" [{status}]" if status else ""
    fig.suptitle(
        f"{name}: one epoch through the chain{why}{status}\n{epoch_summary(ds, epoch)}",
        fontsize="medium",
    )
    return fig


def epoch_status(ds: xr.Dataset, i: int) -> str:
    """Why epoch ``i`` is not (fully) observed, from its flags: "" when it is.

    "eclipsed (in the Earth's shadow)", "in the penumbra (x % of the solar disk)", "below the
    minimum elevation", "in daylight (...)", "no orbit position", "render failed", joined by
    "; ".
    """
    bits = int(flags(ds)[i])
    reasons = [
        text
        for bit, text in (
            (v.FLAG_ORBIT_FAILED, "no orbit position"),
            (v.FLAG_BELOW_MIN_ELEVATION, "below the minimum elevation"),
            (v.FLAG_DAYLIGHT, "in daylight (the Sun above observer.max_sun_elevation_deg)"),
            (v.FLAG_IN_SHADOW, "eclipsed (in the Earth's shadow)"),
            (v.FLAG_RENDER_FAILED, "render failed"),
        )
        if bits & bit
    ]
    if bits & v.FLAG_PENUMBRA and not bits & v.FLAG_IN_SHADOW:
        disk = f" ({100 * _sunlit(ds, i):.0f} % of the solar disk)" if "sunlit" in ds else ""
        reasons.append(f"in the penumbra{disk}")
    return "; ".join(reasons)


def _sunlit(ds: xr.Dataset, i: int) -> float:
    return float(ds["sunlit"].values[i]) if "sunlit" in ds else 1.0


def _solar(ds: xr.Dataset, ax: Any, w: NDArray[np.float64], i: int) -> None:
    # What the target receives: the Sun's spectrum times the visible fraction of its disk
    # (0 in the Earth's shadow); ``solar_irradiance`` is the one before shadowing.
    sunlit = _sunlit(ds, i)
    unshadowed = _row(ds, "solar_irradiance", i)
    where = "eclipsed" if sunlit <= 0 else f"sunlit fraction {sunlit:.2f}"
    ax.plot(w, unshadowed * sunlit, color="C1", lw=1.2, label=f"received by the target\n({where})")
    if sunlit < 1:
        ax.plot(w, unshadowed, color="C1", lw=0.8, ls="--", alpha=0.6, label="outside the shadow")
    ax.set_ylabel("solar irradiance\n[W m$^{-2}$ nm$^{-1}$]")
    ax.set_title("1. Sun", loc="left", fontsize="medium")


def _intensity(ds: xr.Dataset, ax: Any, w: NDArray[np.float64], i: int) -> None:
    y = _row(ds, "intensity", i)
    ax.plot(w, y, color="C0", lw=1.2, label="toward the observer")
    if "intensity_std" in ds:
        s = _row(ds, "intensity_std", i)
        if np.nanmax(s, initial=0.0) > 0:
            ax.fill_between(
                w, y - 2 * s, y + 2 * s, color="C0", alpha=0.3, lw=0, label="±2 std. error"
            )
    ax.set_ylabel("intensity\n[W sr$^{-1}$ nm$^{-1}$]")
    ax.set_title("2. reflection by the target", loc="left", fontsize="medium")


def _transmission(ds: xr.Dataset, ax: Any, w: NDArray[np.float64], i: int) -> None:
    label = "line of sight"
    if "elevation" in ds:
        label += f"\nat elevation {float(ds['elevation'].values[i]):.1f}°"
    ax.plot(w, _row(ds, "transmission", i), color="C2", lw=1.2, label=label)
    ax.set_ylim(-0.03, 1.03)
    ax.set_ylabel("transmission [1]")
    model = ds.attrs.get("atmosphere_model", "")
    ax.set_title(f"3. atmosphere {f'({model})' if model else ''}", loc="left", fontsize="medium")


def _instrument(ds: xr.Dataset, ax: Any, w: NDArray[np.float64], i: int) -> None:
    flux = _row(ds, "spectral_flux", i)
    optics = (
        np.asarray(ds["optics_transmission"].values, dtype=np.float64)
        if "optics_transmission" in ds
        else np.ones_like(w)
    )
    per_band = _per_band(ds, "detector_qe") if "detector_qe" in ds else np.ones((1, w.size))
    qes, which = np.unique(np.round(per_band, 12), axis=0, return_inverse=True)
    unit_qes = [bool(np.allclose(qe, 1.0)) for qe in qes]
    ones = [
        name for name, one in (("optics", np.allclose(optics, 1.0)), ("QE", all(unit_qes))) if one
    ]
    note = f"\n({' and '.join(ones)}: 1)" if ones else ""
    ax.plot(w, flux, color="k", lw=1.2, label=f"at the aperture{note}")
    if not np.allclose(optics, 1.0):
        ax.plot(w, flux * optics, color="0.45", lw=1.2, label="× optics")
    names = [str(b) for b in ds["band"].values] if "band" in ds.coords else []
    drawn = 0
    for k, qe in enumerate(qes):
        if unit_qes[k]:
            continue  # QE 1: same curve as the one above
        users = [n for n, j in zip(names, np.ravel(which), strict=False) if j == k]
        label = "× optics × QE" + (f"\n({', '.join(users)})" if len(qes) > 1 else "")
        ls = ["--", ":", "-."][drawn % 3]
        ax.plot(w, flux * optics * qe, lw=1.2, ls=ls, color="C3", label=label)
        drawn += 1
    ax.set_ylabel("spectral flux\n[W nm$^{-1}$]")
    ax.set_title("4. telescope and detector", loc="left", fontsize="medium")


def band_electron_spectra(ds: xr.Dataset, i: int) -> NDArray[np.float64]:
    """Detected photo-electron spectrum of each band at epoch ``i`` (B, L) [s-1 nm-1].

    :math:`\\Phi_\\lambda\\,\\tau_{opt}\\,\\eta_b\\,R_b\\,\\lambda/(hc)`; its integral over
    wavelength is the band's count rate.
    """
    w = np.asarray(ds["wavelength"].values, dtype=np.float64)
    flux = _row(ds, "spectral_flux", i)
    optics = (
        np.asarray(ds["optics_transmission"].values, dtype=np.float64)
        if "optics_transmission" in ds
        else np.ones_like(w)
    )
    response = _per_band(ds, "band_response")
    qe = _per_band(ds, "detector_qe") if "detector_qe" in ds else np.ones_like(response)
    # W nm-1 x (lambda / hc) [J-1] = photons s-1 nm-1
    return np.asarray(flux * optics * qe * response * (w * 1e-9 / HC_J_M))


def _bands(ds: xr.Dataset, ax: Any, w: NDArray[np.float64], i: int) -> None:
    spectra = band_electron_spectra(ds, i)
    styles = band_styles(ds)
    dlam = np.abs(np.gradient(w)) if w.size > 1 else np.ones_like(w)
    for b, name in enumerate(ds["band"].values):
        dn = spectra[b]
        rate = (
            float(ds["count_rate"].isel(time=i, band=b))
            if "count_rate" in ds
            else float(np.nansum(dn * dlam))
        )
        ax.fill_between(w, 0.0, dn, color=styles[b]["color"], alpha=0.25, lw=0)
        ax.plot(w, dn, lw=1.2, label=f"{name}: {rate:.3g} s$^{{-1}}$", **styles[b])
    ax.set_ylabel("photo-electron rate\ndensity [s$^{-1}$ nm$^{-1}$]")
    gaussian = any(GAUSSIAN_NAME.match(str(name)) for name in ds["band"].values)
    ax.set_title(
        "5. each band: flux × optics × QE × response × λ/hc (legend: count rate"
        + ("; G-c/s: Gaussian, centre c, sigma s [nm], not FWHM)" if gaussian else ")"),
        loc="left",
        fontsize="medium",
    )


_DRAW = {
    "solar_irradiance": _solar,
    "intensity": _intensity,
    "transmission": _transmission,
    "instrument": _instrument,
    "bands": _bands,
}
