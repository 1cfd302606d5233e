"""What a band albedo is, once for every estimator (``fit``, ``upsample``, ``unmix``).

A body of reflectance spectrum ``rho(l)`` sends band j a count rate proportional to
``sum_l rho(l) E(l) R_j(l) l dl`` (Nussbaum et al. 2022, eq. 5, doi:10.3390/aerospace9040214):
``E`` the source spectrum at the aperture (the Sun's irradiance x the sunlit fraction x the
atmosphere's transmission), ``R_j`` the band curve x optics transmission x detector QE,
``l / (h c)`` the photons per joule and ``dl`` the bin width. Its **band albedo** is that
rate's reflectance: the average of ``rho`` weighted as the measurement weighs it,

.. math::

    \\rho_j = \\frac{\\sum_l \\rho(l) E(l) R_j(l) l \\, dl}{\\sum_l E(l) R_j(l) l \\, dl},

with ``E`` the mean source over the pass's usable epochs (lit, observable):
:func:`dataset_mean_source_W_m2_nm` for a simulated dataset, :func:`scenario_mean_source_W_m2_nm`
for a scenario's own pass. It differs from each epoch's exact weights only by the change of
the atmosphere's spectral shape along the pass. With no source (``None``) it is the plain
photon-weighted average of the reference paper's eq. 3 (a flat source).

``fit``'s albedo (a band scale times the scenario's band albedo), ``upsample``'s band
averages and ``unmix``'s band signatures are this one number; a flat-source average differs
from it by several percent where the reflectance changes across a band (a solar cell in a
blue band: 0.2099 against 0.2272).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike, NDArray

from speclight import schema
from speclight.constants import AU_M, HC_J_M
from speclight.errors import InputError
from speclight.wavelength_grid import bin_widths_nm, check_wavelength_grid

if TYPE_CHECKING:
    from speclight.scenario import LoadedScenario

F64 = NDArray[np.float64]
#: Flag bits of an epoch whose source does not enter the mean (not seen, or no sunlight).
UNUSABLE_FLAGS = (
    schema.FLAG_ORBIT_FAILED
    | schema.FLAG_BELOW_MIN_ELEVATION
    | schema.FLAG_IN_SHADOW
    | schema.FLAG_DAYLIGHT
)
#: At most this many epochs, evenly spread over the usable ones, make a scenario's mean source.
SOURCE_EPOCHS = 200


def photon_weights(
    band_response: ArrayLike, wavelength_nm: ArrayLike, source_W_m2_nm: ArrayLike | None = None
) -> F64:
    """Normalised weights of a band albedo [1] (B, L): ``E R_j l / (h c) dl`` over its sum.

    Parameters
    ----------
    band_response
        Band responses on the grid (B, L) (band response x optics x QE) [1].
    wavelength_nm
        The grid [nm] (L,).
    source_W_m2_nm
        The source spectrum at the aperture (L,) [W m-2 nm-1] (module doc); None: flat.

    Returns
    -------
    numpy.ndarray
        Weights whose rows sum to 1; ``weights @ rho`` are the band albedos of ``rho``.
    """
    wl = np.asarray(wavelength_nm, dtype=np.float64)
    photons = np.asarray(band_response, dtype=np.float64) * (wl * 1e-9 / HC_J_M)
    if source_W_m2_nm is not None:
        photons = photons * np.asarray(source_W_m2_nm, dtype=np.float64)
    w = photons * bin_widths_nm(wl)
    return np.asarray(w / w.sum(axis=-1, keepdims=True), dtype=np.float64)


def band_albedo(
    reflectance: ArrayLike,
    band_response: ArrayLike,
    wavelength_nm: ArrayLike,
    source_W_m2_nm: ArrayLike | None = None,
) -> F64:
    """Band albedos (B,) [1] of a reflectance spectrum (module doc).

    Parameters
    ----------
    reflectance
        The spectrum on the grid [1] (L,).
    band_response
        Band responses on the grid (B, L) [1].
    wavelength_nm
        The grid [nm] (L,).
    source_W_m2_nm
        The source spectrum at the aperture (L,) [W m-2 nm-1]; None: flat (eq. 3).
    """
    wl, response = check_band_response(band_response, wavelength_nm)
    g = np.asarray(reflectance, dtype=np.float64)
    if g.shape != wl.shape:
        raise InputError(
            f"reflectance has shape {g.shape}, expected {wl.shape} (one value per wavelength)",
            field="reflectance",
        )
    source = check_source(source_W_m2_nm, wl, response)
    return np.asarray(photon_weights(response, wl, source) @ g, dtype=np.float64)


def check_source(source_W_m2_nm: ArrayLike | None, wavelength_nm: F64, response: F64) -> F64 | None:
    """The source spectrum (L,) checked: finite, >= 0, light in every band (None passes)."""
    if source_W_m2_nm is None:
        return None
    source = np.asarray(source_W_m2_nm, dtype=np.float64)
    if source.shape != wavelength_nm.shape or not np.all(np.isfinite(source)):
        raise InputError(
            f"source_W_m2_nm must be finite with shape {wavelength_nm.shape}",
            field="source_W_m2_nm",
        )
    if np.any(source < 0):
        raise InputError("source_W_m2_nm must be >= 0", field="source_W_m2_nm")
    dark = np.flatnonzero(~(response @ source > 0))
    if dark.size:
        raise InputError(
            f"source_W_m2_nm is zero in band rows {dark.tolist()}: they receive no light",
            field="source_W_m2_nm",
        )
    return source


def check_band_response(band_response: ArrayLike, wavelength_nm: ArrayLike) -> tuple[F64, F64]:
    """The grid and the responses (B, L) checked: finite, >= 0, each band non-zero."""
    try:
        wl = check_wavelength_grid(wavelength_nm)
    except InputError as err:
        raise InputError(err.message, field="wavelength_nm") from None
    response = np.asarray(band_response, dtype=np.float64)
    if response.ndim != 2 or response.shape[1] != wl.size:
        raise InputError(
            f"band_response has shape {response.shape}, expected (n_bands, {wl.size}) "
            f"(one row per band on the {wl.size}-point wavelength grid)",
            field="band_response",
        )
    if not np.all(np.isfinite(response)) or np.any(response < 0):
        raise InputError("band_response must be finite and >= 0", field="band_response")
    empty = np.flatnonzero(~(response.sum(axis=1) > 0))
    if empty.size:
        raise InputError(
            f"band_response rows {empty.tolist()} are zero on the whole wavelength grid "
            "(each band needs some response inside the grid)",
            field="band_response",
        )
    return wl, response


def _mean_lit(source: F64, usable: NDArray[np.bool_]) -> F64 | None:
    lit = usable & np.all(np.isfinite(source), axis=1) & np.any(source > 0, axis=1)
    return np.asarray(source[lit].mean(axis=0)) if np.any(lit) else None


def dataset_mean_source_W_m2_nm(ds: xr.Dataset) -> F64 | None:
    """The mean Sun at the aperture (L,) over the usable epochs of a ``speclight simulate``
    dataset: ``solar_irradiance x sunlit x transmission`` where no flag of
    :data:`UNUSABLE_FLAGS` is set; None where the dataset has no lit usable epoch."""
    from speclight.estimate.inputs.source_spectrum import sun_source_W_m2_nm

    source = sun_source_W_m2_nm(ds)
    usable = np.ones(len(source), dtype=bool)
    if "flags" in ds:
        usable = (ds["flags"].values.astype(int) & UNUSABLE_FLAGS) == 0
    return _mean_lit(source, usable)


def scenario_mean_source_W_m2_nm(loaded: LoadedScenario) -> F64 | None:
    """The mean Sun at the aperture (L,) over the scenario's own pass (its time grid):
    ``solar_irradiance x sunlit x transmission`` at up to :data:`SOURCE_EPOCHS` of the lit,
    observable epochs (geometry and atmosphere only, no render); None for a scenario
    without the Sun or whose pass has no such epoch."""
    from speclight.illumination import solar_irradiance_W_m2_nm
    from speclight.simulation.geometry_stage import scenario_geometry
    from speclight.simulation.radiometry import atmosphere_transmission, wavelength_grid_nm

    sc = loaded.scenario
    if not sc.illumination.sun:
        return None
    geo = scenario_geometry(loaded)
    usable = np.flatnonzero(geo.observable & (geo.sunlit_fraction > 0))
    if usable.size == 0:
        return None
    pick = usable[np.unique(np.linspace(0, usable.size - 1, SOURCE_EPOCHS).round().astype(int))]
    wl = wavelength_grid_nm(sc.spectrum)
    solar = solar_irradiance_W_m2_nm(wl, geo.sun_distance_m[pick] / AU_M)
    transmission = atmosphere_transmission(loaded, wl, geo.elevation_deg[pick])
    source = solar * geo.sunlit_fraction[pick, None] * transmission
    return _mean_lit(source, np.ones(pick.size, dtype=bool))
