"""False-alarm probability of a multi-band periodogram peak, by a permutation bootstrap.

astropy's multi-band periodogram has no false-alarm probability. Here it is estimated as in
Suveges (2012, "False alarm probability based on bootstrap and extreme-value methods for
periodogram peaks", ESA-GAIA-CU7-TN-GEN-MS-001) and VanderPlas (2018, ApJS 236, 16, 7.4):
``draws`` times, the (value, sigma) pairs of each band are shuffled among that band's epochs
(the times stay, so the window function and cadence stay, but any periodicity is destroyed),
the periodogram is computed on the same frequency grid, and its maximum kept. A Gumbel
distribution (the extreme-value law of a maximum over many nearly independent frequencies)
is fitted to the maxima by maximum likelihood (scipy.stats.gumbel_r), and the false-alarm
probability of an observed peak of power ``p`` is its survival function at ``p`` (Suveges
2014, MNRAS 440, 2099, doi:10.1093/mnras/stu380, fit a generalised extreme-value law; the
Gumbel law is its shape-0 case, stable with few draws): this reaches below ``1/draws``,
where counting cannot. The plain permutation p-value ``(1 + #{max_i >= p}) / (1 + draws)``
(an upper bound when no draw reaches ``p``) is reported beside it. ``power_at(0.01)`` is the
power whose fitted false-alarm probability is 1 %, marked in the figure.

The draws run in parallel threads (astropy's periodogram spends its time in numpy, which
releases the interpreter lock); each draw has its own random stream spawned from ``seed``
(numpy's ``SeedSequence.spawn``), so the result does not depend on the number of threads.
The bootstrap is what ``speclight period --fap bootstrap`` computes; by default the
analytic approximation of :mod:`.analytic_fap` replaces it where it is valid.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from speclight.estimate.period.periodogram import F64, BandSeries, multiband_power

#: Default number of bootstrap draws and seed.
DRAWS = 40
SEED = 0


@dataclass
class BootstrapMaxima:
    """Periodogram maxima of permuted light curves."""

    maxima: F64
    seed: int

    @property
    def draws(self) -> int:
        """Number of draws."""
        return int(self.maxima.size)

    def _gumbel(self) -> tuple[float, float]:
        from scipy.stats import gumbel_r

        if np.ptp(self.maxima) <= 0:
            return float(self.maxima[0]), 1e-12
        # the maximum-likelihood search tries scales at which exp(-x) overflows (to inf,
        # correctly ignored by the fit): not the user's concern (a fuzz run printed 22)
        with np.errstate(over="ignore"):
            loc, scale = gumbel_r.fit(self.maxima)
        return float(loc), float(scale)

    def false_alarm_probability(self, power: float) -> float:
        """Gumbel-fit false-alarm probability of a peak of ``power`` (module docstring)."""
        from scipy.stats import gumbel_r

        loc, scale = self._gumbel()
        with np.errstate(over="ignore"):  # exp(-x) of a power far below loc: sf 1, exactly
            return float(gumbel_r.sf(power, loc, scale))

    def permutation_p_value(self, power: float) -> tuple[float, bool]:
        """``((1 + k) / (1 + draws), k == 0)``, ``k`` the draws whose maximum reaches ``power``
        (with ``k == 0`` an upper bound)."""
        k = int(np.sum(self.maxima >= power))
        return (1 + k) / (1 + self.draws), k == 0

    def power_at(self, fap: float) -> float:
        """The power whose Gumbel-fit false-alarm probability is ``fap``."""
        from scipy.stats import gumbel_r

        loc, scale = self._gumbel()
        return float(gumbel_r.isf(fap, loc, scale))


def bootstrap_maxima(
    series: BandSeries, frequency_hz: F64, harmonics: int, draws: int = DRAWS, seed: int = SEED
) -> BootstrapMaxima:
    """Periodogram maxima of ``draws`` permutations of ``series`` (module docstring).

    Parameters
    ----------
    series
        The light curves.
    frequency_hz
        The frequency grid searched [Hz].
    harmonics
        Harmonics of the periodogram's model.
    draws
        Permutations.
    seed
        Seed of the permutations.
    """
    import os
    from concurrent.futures import ThreadPoolExecutor

    streams = np.random.SeedSequence(seed).spawn(draws)

    def one(stream: np.random.SeedSequence) -> float:
        permuted = series.permuted(np.random.default_rng(stream))
        return float(np.nanmax(multiband_power(permuted, frequency_hz, harmonics)))

    workers = max(1, min(draws, os.cpu_count() or 1))
    with ThreadPoolExecutor(max_workers=workers) as pool:
        maxima = np.fromiter(pool.map(one, streams), dtype=float, count=draws)
    return BootstrapMaxima(maxima, seed)
