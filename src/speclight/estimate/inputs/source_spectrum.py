"""The source spectrum at the aperture, which weights the band signatures of materials.

The band reflectance factor (eq. 5 of Nussbaum et al. 2022,
doi:10.3390/aerospace9040214) divides the band rate by the band-weighted source photon flux
at the aperture, ``integral(E(l) T(l) R_j(l) l dl)``. A material of reflectance ``rho(l)``
therefore enters the factor through its **source-weighted** band average
``sum rho E T R_j l dl / sum E T R_j l dl`` (:func:`speclight.estimate.spectra.ground_truth.
material_signatures`), with ``E T`` the spectrum returned here, per epoch (N, L):

* the Sun: ``solar_irradiance x sunlit x transmission`` of a ``speclight simulate`` dataset;
* lasers transmitted from the observer's site (coaxial): each line ``beam x shape x T`` at
  the target (``laser_irradiance`` its integral over the bins) and ``x T`` again at the aperture
  (:func:`coaxial_laser_source_W_m2_nm`), the line shapes from the scenario.

A transmitter elsewhere has an uplink transmission of its own, not in the dataset; the
observer's is used for it, with a notice.
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING, Literal

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError
from speclight.wavelength_grid import grid_bin_bounds_nm

if TYPE_CHECKING:
    from speclight.scenario import LoadedScenario

F64 = NDArray[np.float64]
Light = Literal["sun", "laser"]
LIGHTS: tuple[str, ...] = ("sun", "laser")


def mean_source_W_m2_nm(
    irradiance_W_m2_nm: ArrayLike, transmission: ArrayLike, weight: ArrayLike | None = None
) -> F64:
    """Source spectrum at the aperture (L,): the mean over epochs of irradiance x transmission.

    ``irradiance_W_m2_nm`` (N, L) at the target (a simulate output's ``solar_irradiance``,
    or the lasers' lines), ``transmission`` (N, L); epochs with a non-finite value, or with a
    zero ``weight`` (N,) (e.g. ``sunlit``), are left out. The signatures weighted with it
    differ from each epoch's exact weights only by the change of the atmosphere's spectral
    shape over the pass.
    """
    e = np.asarray(irradiance_W_m2_nm, dtype=np.float64) * np.asarray(transmission, dtype=float)
    ok = np.all(np.isfinite(e), axis=1) & np.any(e > 0, axis=1)
    if weight is not None:
        ok &= np.asarray(weight, dtype=np.float64) > 0
    if not np.any(ok):
        raise InputError("no epoch with a finite, lit source spectrum", field="irradiance")
    return np.asarray(e[ok].mean(axis=0))


def coaxial_laser_source_W_m2_nm(
    laser_irradiance_W_m2: ArrayLike,
    line_per_nm: ArrayLike,
    transmission: ArrayLike,
    wavelength_nm: ArrayLike,
) -> F64:
    """Lasers' spectrum at the aperture (N, L) for transmitters at the observer's site.

    ``laser_irradiance_W_m2`` (N, K) is the simulate output's ``laser_irradiance`` (each
    line's irradiance at the target, after the uplink), ``line_per_nm`` (K, L) the line
    shapes on the grid ``wavelength_nm`` (on their support, as the pipeline keeps them) and
    ``transmission`` (N, L) the observer's. From the observer's own site the uplink has the
    downlink's transmission T, so a line at the target is ``beam x shape x T``
    [W m-2 nm-1] (``laser_irradiance`` its integral over the grid's bins, as the pipeline
    sums it) and at the aperture ``beam x shape x T^2``.
    """
    irr = np.asarray(laser_irradiance_W_m2, dtype=np.float64)
    lines = np.atleast_2d(np.asarray(line_per_nm, dtype=np.float64))
    t = np.asarray(transmission, dtype=np.float64)
    lo, hi = grid_bin_bounds_nm(np.asarray(wavelength_nm, dtype=np.float64))
    out = np.zeros_like(t)
    for k in range(len(lines)):
        shaped = lines[k] * t
        with np.errstate(invalid="ignore", divide="ignore"):
            beam = np.where(irr[:, k] > 0, irr[:, k] / (shaped @ (hi - lo)), 0.0)
        out += beam[:, None] * shaped
    return np.asarray(out * t)


def laser_lines_per_nm(loaded: LoadedScenario, wavelength_nm: ArrayLike) -> F64:
    """The scenario's laser lines (K, L) [nm-1] on the grid, zero off their support (as
    :mod:`speclight.simulation.ranging_stage` keeps them); a notice for a transmitter that is
    not at the observer's site (its uplink transmission is taken as the observer's)."""
    from speclight.simulation.ranging_stage import SUPPORT_THRESHOLD, line_shape_per_nm

    sc = loaded.scenario
    wl = np.asarray(wavelength_nm, dtype=np.float64)
    lines = []
    for k, cfg in enumerate(sc.illumination.lasers):
        shape = line_shape_per_nm(loaded, cfg, wl, f"illumination.lasers[{k}]")
        lines.append(np.where(shape > SUPPORT_THRESHOLD * shape.max(), shape, 0.0))
        site = (cfg.latitude_deg, cfg.longitude_deg, cfg.altitude_m)
        obs = (sc.observer.latitude_deg, sc.observer.longitude_deg, sc.observer.altitude_m)
        if not np.allclose(site, obs, rtol=0, atol=1e-6):
            warnings.warn(
                f"laser {cfg.name} is not at the observer's site: its uplink transmission is "
                "taken as the observer's for the band signatures",
                stacklevel=2,
            )
    if not lines:
        raise InputError("the scenario has no lasers", field="illumination.lasers")
    return np.stack(lines)


def sun_source_W_m2_nm(ds: xr.Dataset) -> F64:
    """``solar_irradiance x sunlit x transmission`` (N, L) of a simulate dataset."""
    missing = [v for v in ("solar_irradiance", "transmission") if v not in ds]
    if missing:
        raise InputError(
            f"the dataset has no {' or '.join(missing)}(time, wavelength): the band "
            "signatures need the source spectrum at the aperture (eq. 5, docs/upsample-unmix.md)",
            field="MEASURED",
        )
    e = ds["solar_irradiance"].transpose("time", "wavelength").values.astype(float)
    t = ds["transmission"].transpose("time", "wavelength").values.astype(float)
    sunlit = ds["sunlit"].values.astype(float) if "sunlit" in ds else np.ones(len(e))
    return np.asarray(e * sunlit[:, None] * t)


def laser_source_W_m2_nm(ds: xr.Dataset, loaded: LoadedScenario) -> F64:
    """The lasers' spectrum at the aperture (N, L) of a simulate dataset (module doc)."""
    if "laser_irradiance" not in ds or "transmission" not in ds:
        raise InputError(
            "the dataset has no laser_irradiance(time, laser) and transmission: it was not "
            "simulated with lasers",
            field="light",
        )
    wl = ds["wavelength"].values
    return coaxial_laser_source_W_m2_nm(
        ds["laser_irradiance"].transpose("time", "laser").values,
        laser_lines_per_nm(loaded, wl),
        ds["transmission"].transpose("time", "wavelength").values,
        wl,
    )


def default_light(ds: xr.Dataset) -> Light:
    """``laser`` where the dataset has laser factors and no finite solar ones, else ``sun``."""
    solar = "reflectance_factor" in ds and bool(np.any(np.isfinite(ds["reflectance_factor"])))
    return "laser" if "laser_reflectance_factor" in ds and not solar else "sun"


def check_light(light: str | None) -> None:
    """Refuse an unknown ``light`` (the command line's ``--source``)."""
    if light is not None and light not in LIGHTS:
        raise InputError(
            f"light = '{light}': unknown source (choices: {', '.join(LIGHTS)})", field="light"
        )
