"""Reflection stage from a reflectivity map (``render.mode: map``): no rendering."""

from __future__ import annotations

import warnings

import numpy as np
from numpy.typing import NDArray

from speclight import schema
from speclight.constants import AU_M
from speclight.illumination import solar_irradiance_W_m2_nm
from speclight.maps.map_lookup import load_map
from speclight.scenario import LoadedScenario
from speclight.simulation.geometry_stage import Geometry
from speclight.simulation.reflection import Reflection

F64 = NDArray[np.float64]


def map_reflection(loaded: LoadedScenario, geo: Geometry, wavelength_nm: F64) -> Reflection:
    """Intensity interpolated from the scenario's map (see :mod:`speclight.maps.map_lookup`).

    The map holds the intensity under the Sun at 1 AU; each epoch's is scaled by the solar
    spectrum at its Sun distance over the one at 1 AU (``1 / d^2``) and by the sunlit
    fraction (penumbra), as a render would be. Unlit epochs get 0, unobservable ones NaN,
    and ``intensity_std`` is 0 (the interpolation error is documented, not estimated).
    """
    sc = loaded.scenario
    assert sc.render.map_file is not None
    solar = solar_irradiance_W_m2_nm(wavelength_nm, geo.sun_distance_m / AU_M)
    n = geo.t_s.size
    intensity = np.full((n, wavelength_nm.size), np.nan)
    observable = geo.observable
    sunlit = geo.sunlit_fraction if sc.illumination.sun else np.zeros(n)
    lit = observable & (sunlit > 0)
    intensity[observable & ~lit] = 0.0
    idx = np.flatnonzero(lit)
    if idx.size:
        the_map = load_map(loaded.resolve(sc.render.map_file))
        _warn_outside(the_map.header.phase_angle_deg, geo.phase_angle_deg[idx])
        at_1au = the_map.intensity_1au(
            geo.sun_direction_body[idx], geo.observer_direction_body[idx]
        )
        solar_1au = solar_irradiance_W_m2_nm(wavelength_nm, 1.0)
        with np.errstate(invalid="ignore", divide="ignore"):
            ratio = np.where(solar_1au > 0, solar[idx] / solar_1au, 0.0)
        intensity[idx] = at_1au * ratio * sunlit[idx, None]
    std = np.where(np.isfinite(intensity), 0.0, np.nan)
    return Reflection(
        solar_irradiance_W_m2_nm=solar,
        intensity_W_sr_nm=intensity,
        intensity_std_W_sr_nm=std,
        variant="map",
        flags=np.zeros(n, dtype=schema.FLAG_DTYPE),
    )


def _warn_outside(stored_deg: F64, phase_deg: F64) -> None:
    """A notice when epochs' phase angles lie outside the map's (they are clamped)."""
    lo, hi = float(stored_deg[0]), float(stored_deg[-1])
    outside = int(np.count_nonzero((phase_deg < lo - 0.5) | (phase_deg > hi + 0.5)))
    if outside:
        warnings.warn(
            f"{outside} epochs have phase angles outside the map's {lo:g}..{hi:g} deg "
            f"(this pass: {np.nanmin(phase_deg):.0f}..{np.nanmax(phase_deg):.0f} deg); they "
            "take the nearest stored phase angle: make the map with --phase-angles-deg "
            "covering the pass",
            stacklevel=2,
        )
