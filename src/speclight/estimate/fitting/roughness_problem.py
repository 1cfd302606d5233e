"""The roughness fit's objective: chi-square over the roughness, the band scales projected out.

Variable projection (Golub & Pereyra 1973, doi:10.1137/0710036): for roughness values
``alpha`` (K,) the model ``c(alpha)`` (N, B) is simulated once (cached) and the band scales
are solved in closed form (:func:`speclight.estimate.fitting.fit.scale_fit`), so that the
objective is a function of the roughness alone, ``chi2(alpha)`` (with a Poisson noise model,
the deviance; :mod:`.noise_model`). :class:`RoughnessProblem` holds that function, the
model's cache and the numbers every stage of the fit shares (the number of data, the
reduced chi-square); the scan (:mod:`.roughness_scan`), the local methods
(:mod:`.roughness_fit`, :mod:`.gradient_fit`) and the uncertainties
(:mod:`.roughness_uncertainty`) all use it.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.fitting.fit import F64, ScaleFit, scale_fit
from speclight.estimate.fitting.noise_model import Likelihood, PoissonNoise

#: Roughness values are rounded to this before simulating (the cache key) [1].
ROUGHNESS_RESOLUTION = 1e-9

Model = Callable[[F64], F64]
GradientModel = Callable[[F64], tuple[F64, F64]]


class RoughnessProblem:
    """``chi2(alpha)`` of a roughness fit with the scales projected out (module doc).

    Parameters
    ----------
    model
        ``model(alpha)`` -> (N, B) simulated rates [s-1]; with ``derivatives``, ->
        ((N, B) rates, (K, N, B) their derivatives in the K roughness values [s-1]).
    measured
        (N, B) measured rates [s-1]; NaN: not used.
    sigma
        (N, B) their standard deviations [s-1], or a :class:`.noise_model.PoissonNoise`.
    bounds
        Lower and upper bound of every roughness [1].
    fit_scale
        Fit a scale per band (else the scales stay 1).
    derivatives
        ``model`` returns the derivatives too.
    on_evaluation
        Called with (number of evaluations, alpha, chi2) after each new simulation.
    """

    def __init__(
        self,
        model: Model | GradientModel,
        measured: F64,
        sigma: F64 | PoissonNoise,
        bounds: tuple[float, float],
        *,
        fit_scale: bool = True,
        derivatives: bool = False,
        on_evaluation: Callable[[int, F64, float], None] | None = None,
    ) -> None:
        self.model = model
        self.likelihood = Likelihood(measured, sigma)
        self.lo, self.hi = float(bounds[0]), float(bounds[1])
        self.fit_scale = fit_scale
        self.derivatives = derivatives
        self.on_evaluation = on_evaluation
        self.cache: dict[tuple[float, ...], tuple[F64, F64 | None]] = {}
        self._n_data: int | None = None

    def key(self, alpha: F64) -> tuple[float, ...]:
        """The cache key of ``alpha``: clipped to the bounds, on the resolution's grid."""
        a = np.clip(np.asarray(alpha, dtype=float), self.lo, self.hi)
        return tuple(float(x) for x in np.round(a / ROUGHNESS_RESOLUTION))

    def seed(self, alpha: F64, rates: F64) -> None:
        """Put an already simulated model (without derivatives) in the cache."""
        if not self.derivatives:
            self.cache[self.key(alpha)] = (np.asarray(rates, dtype=float), None)

    def evaluate(self, alpha: F64) -> tuple[F64, F64 | None]:
        """The model (and its derivatives) at ``alpha``, simulated once per distinct value."""
        key = self.key(alpha)
        if key not in self.cache:
            value = self.model(np.array(key) * ROUGHNESS_RESOLUTION)
            if self.derivatives:
                c, dc = value
                self.cache[key] = (np.asarray(c, dtype=float), np.asarray(dc, dtype=float))
            else:
                self.cache[key] = (np.asarray(value, dtype=float), None)
            if self.on_evaluation is not None:
                self.on_evaluation(len(self.cache), np.array(key) * ROUGHNESS_RESOLUTION,
                                   self.chi2(alpha))  # fmt: skip
        return self.cache[key]

    def rates(self, alpha: F64) -> F64:
        """(N, B) the simulated rates at ``alpha`` [s-1]."""
        return self.evaluate(alpha)[0]

    def scales(self, alpha: F64) -> ScaleFit:
        """The band scales at ``alpha`` (ones, with their deviance, when not fitted)."""
        c = self.rates(alpha)
        fit = scale_fit(self.likelihood, c)
        if self.fit_scale:
            return fit
        n_b = c.shape[1]
        chi2 = self.likelihood.deviance(c)
        return ScaleFit(np.ones(n_b), np.zeros(n_b), chi2, fit.n_used)

    def chi2(self, alpha: F64) -> float:
        """The chi-square (deviance) at ``alpha`` with the scales at their optimum."""
        return float(np.sum(self.scales(alpha).chi2))

    def fitted(self, alpha: F64) -> F64:
        """(N, B) the scaled model at ``alpha`` [s-1]."""
        s = self.scales(alpha).scale
        return np.where(np.isfinite(s), s, 0.0)[None, :] * self.rates(alpha)

    @property
    def n_data(self) -> int:
        """Measurements fitted (those the first model evaluated covers)."""
        if self._n_data is None:
            first = next(iter(self.cache.values()))[0]
            self._n_data = int(np.count_nonzero(self.likelihood.mask(first)))
        return self._n_data

    def n_par(self, k: int) -> int:
        """Parameters fitted with ``k`` roughness values."""
        return k + (self.likelihood.m.shape[1] if self.fit_scale else 0)

    def unit(self, chi2: float, k: int) -> float:
        """The reduced chi-square of a fit of ``k`` roughness values, at least 1: the size of
        a change of chi2 that one standard deviation of a parameter makes."""
        return max(1.0, chi2 / max(self.n_data - self.n_par(k), 1))

    def without(self, drop: NDArray[np.bool_]) -> RoughnessProblem:
        """The same problem, sharing the cache, with the entries ``drop`` (N, B) left out."""
        out = object.__new__(RoughnessProblem)
        out.__dict__.update(self.__dict__)
        out.likelihood = self.likelihood.without(drop)
        out._n_data = None
        return out


__all__ = ["ROUGHNESS_RESOLUTION", "GradientModel", "Model", "RoughnessProblem"]
