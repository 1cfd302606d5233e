"""Count rates of a scenario and their analytic derivatives in the roughness (fit model).

:class:`RoughnessRates` runs the pipeline's reflection -> atmosphere -> instrument chain on a
fixed geometry (the fit's first simulation) for the epochs a fit uses, with the render's
roughness derivatives (:func:`speclight.render.single_gradient.render_single_gradient`):
the atmosphere and the instrument are linear in the intensity, so the derivative of the
count rate is the same chain applied to the derivative of the intensity,

    dC_tj/dalpha_k = A / r_t^2 * sum_lambda T_t(lambda) dI_t/dalpha_k(lambda) ... (band j)

with the penumbra's sunlit fraction, the articulated parts' poses and the Earthshine cells
as in the pipeline (:class:`speclight.simulation.reflection_gradient.ReflectionGradient`). The
rates equal ``simulate``'s ``count_rate`` at those epochs (the same sums;
tests/estimate/test_fit_gradient.py, tests/estimate/test_fit_gradient_scenes.py).

Supported: single-scattering render of ``beckmann`` and ``ggx`` materials, with the Sun,
Earthshine and articulated parts (:func:`gradient_problems` says what is not).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from speclight import instrument
from speclight.render.single_gradient import gradient_problem
from speclight.scenario import LoadedScenario
from speclight.simulation.geometry_stage import Geometry
from speclight.simulation.radiometry import (
    atmosphere_transmission,
    instrument_response,
    wavelength_grid_nm,
)
from speclight.simulation.reflection import build_target
from speclight.simulation.reflection_gradient import ReflectionGradient

F64 = NDArray[np.float64]


def gradient_problems(loaded: LoadedScenario, rough: list[str]) -> list[str]:
    """Why the analytic roughness gradient cannot be used for this scenario ([] if it can)."""
    sc = loaded.scenario
    out = []
    if sc.render.mode != "single":
        out.append(
            f"render.mode is '{sc.render.mode}': derivatives exist for the single-scattering "
            "render only (set render.mode: single, or use method='slsqp')"
        )
    if sc.target is not None:
        target = build_target(loaded)
        for m in target.materials:
            if m.name in rough and gradient_problem(m):
                out.append(gradient_problem(m))
    return out


class RoughnessRates:
    """``rates(alpha)`` -> count rates (N, B) [s-1] and d rates / d alpha (K, N, B).

    Parameters
    ----------
    loaded
        The scenario (its ``instrument.noise`` off: :func:`gradient_problems` passed).
    geometry
        The geometry of a simulation of ``loaded`` at the fit's epochs.
    rough
        Names of the K rough materials (keys of ``target.materials``).
    use
        (N,) epochs to compute; the others are NaN.
    """

    def __init__(
        self, loaded: LoadedScenario, geometry: Geometry, rough: list[str], use: NDArray[np.bool_]
    ) -> None:
        sc = loaded.scenario
        geo = geometry
        self.rough = list(rough)
        self.wavelength_nm = wavelength_grid_nm(sc.spectrum)
        self.n = geo.t_s.size
        self.seen = np.flatnonzero(use & geo.observable)
        self.reflection = ReflectionGradient(loaded, geo, self.wavelength_nm, self.rough, self.seen)
        elevation = np.where(geo.observable, geo.elevation_deg, np.nan)
        transmission = atmosphere_transmission(loaded, self.wavelength_nm, elevation)
        self.transmission = transmission[self.seen]
        self.range_m = geo.range_m[self.seen]
        zero = np.zeros((self.n, self.wavelength_nm.size))
        curves = instrument_response(loaded, self.wavelength_nm, zero, transmission, geo.range_m)
        self.kernel = curves.band_response * curves.qe
        self.optics = curves.optics
        self.area_m2 = instrument.aperture_area_m2(
            sc.telescope.aperture_diameter_m, sc.telescope.obstruction_diameter_m
        )
        self.n_bands = self.kernel.shape[0]
        self.calls = 0

    def _rates(self, intensity: F64) -> F64:
        flux = instrument.spectral_flux_W_nm(
            intensity, self.transmission, self.area_m2, self.range_m
        )
        ones = np.ones(self.wavelength_nm.size)
        return instrument.count_rate_per_s(flux, self.wavelength_nm, self.optics, ones, self.kernel)

    def __call__(self, alpha: F64) -> tuple[F64, F64]:
        """Count rates (N, B) and their derivatives (K, N, B) at roughness ``alpha`` (K,)."""
        self.calls += 1
        k = len(self.rough)
        rates = np.full((self.n, self.n_bands), np.nan)
        jac = np.full((k, self.n, self.n_bands), np.nan)
        if self.seen.size == 0:
            return rates, jac
        intensity, d_intensity = self.reflection(np.asarray(alpha, dtype=float))
        rates[self.seen] = self._rates(intensity)
        for j in range(k):
            jac[j, self.seen] = self._rates(d_intensity[j])
        return rates, jac


__all__ = ["RoughnessRates", "gradient_problems"]
