"""How measured rates scatter about the model: the likelihood that ``speclight fit`` minimises.

Two noise models (docs/fit.md, "Weights and likelihood"):

* **given sigmas** (a CSV's ``<band>_sigma`` columns, a NetCDF's ``count_rate_sigma``): the
  rates are Gaussian about the model with those standard deviations, and the fit minimises
  ``chi2 = sum ((m - mu) / sigma)^2``; the scales are a weighted linear least-squares
  problem, in closed form;
* **none given** (:class:`PoissonNoise`): the detected electrons are Poisson about the
  **model's** electrons, ``lambda = (mu + B) T + sigma_r^2`` for a rate ``mu`` integrated
  over ``T`` seconds, with the background rate ``B`` (sky and dark current, subtracted from
  the measured rate) and the read noise ``sigma_r`` where the scenario's ``instrument.noise``
  gives them (a Gaussian read noise is close to a Poisson count of variance
  ``sigma_r^2``). The fit minimises the Poisson deviance (McCullagh & Nelder 1989,
  *Generalized Linear Models*, section 6.2, doi:10.1007/978-1-4899-3242-6)

  .. math::

      D = 2 \\sum [\\lambda - n + n \\ln(n / \\lambda)],\\qquad n = (m + B) T + \\sigma_r^2,

  which is the chi-square of a Poisson likelihood ratio: about the number of degrees of
  freedom at the truth, and a change of 1 for one standard deviation of one parameter.
  ``lambda`` is floored at one electron (:data:`FLOOR_E`), so that an epoch where the model
  is dark does not weigh infinitely.

Why the model and not the data: the sigma of a measured rate taken from the rate itself
(``sqrt(m T) / T``, Neyman's chi-square) weights every rate that noise made low more than one
that noise made high, which biases the scales low (by about one count per epoch of the
sum); and where the model's glints are misplaced, it gives the dark measured epochs where
the model glints an almost infinite weight, which drives the scale to zero (issue 25: an
albedo of 0.0005 for a true 0.7). The model's own variance has neither effect: the scales
solve the Poisson score equation ``sum (n - lambda) / lambda * c T = 0`` (for ``B = 0`` it
is ``sum m T / sum c T``, the Poisson maximum-likelihood scale).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.fitting.fit_bins import EpochBins

F64 = NDArray[np.float64]

#: Smallest modelled electron count of a measurement [e]: one detected electron.
FLOOR_E = 1.0
#: Fisher-scoring iterations of the Poisson scales, at most.
MAX_SCORING = 60
#: ... which stop when a step changes a scale by less than this, relative [1].
SCORING_TOL = 1e-12


@dataclass(frozen=True)
class PoissonNoise:
    """The model's own noise (module doc): integration time and background of each rate.

    Attributes
    ----------
    exposure_s
        (N, B) seconds of light integrated into each measured rate (the exposure time times
        the number of exposures averaged) [s].
    background_e
        (N, B) electrons added to the signal's own in that time: the subtracted sky and dark
        counts plus the read-noise variance, ``(B_sky + D) T + n sigma_r^2`` [e]; 0 where the
        scenario gives no noise block.
    given_sigma
        (N, B) the measurements' own standard deviations [s-1] where the data give them (NaN
        elsewhere), or None: where finite, such an entry is Gaussian with that sigma.
    """

    exposure_s: F64
    background_e: F64
    given_sigma: F64 | None = None

    @classmethod
    def of(
        cls,
        shape: tuple[int, int],
        exposure_s: float,
        n_samples: NDArray | int = 1,
        background_per_s: F64 | float = 0.0,
        read_noise_e: float = 0.0,
        given_sigma: F64 | None = None,
    ) -> PoissonNoise:
        """The noise of (N, B) rates, each the mean of ``n_samples`` (N,) exposures of
        ``exposure_s`` [s], over a background of ``background_per_s`` (B,) [s-1] and a read
        noise of ``read_noise_e`` [e rms] per exposure; ``given_sigma`` as the attribute."""
        n = np.asarray(n_samples, dtype=float)
        n = np.broadcast_to(n[:, None] if n.ndim == 1 else n, shape)
        t = float(exposure_s) * n
        b = np.broadcast_to(np.asarray(background_per_s, dtype=float), shape)
        return cls(np.array(t), np.array(b * t + n * float(read_noise_e) ** 2), given_sigma)

    def binned(self, bins: EpochBins) -> PoissonNoise:
        """The noise of the bins' mean rates (:mod:`.fit_bins`): the exposures and the
        background electrons of a bin's entries add up."""
        count = np.where(bins.count > 0, bins.count, np.nan)
        given = None if self.given_sigma is None else bins.sigma(self.given_sigma)
        return PoissonNoise(bins.mean(self.exposure_s) * count,
                            bins.mean(self.background_e) * count, given)  # fmt: skip


def _sum(x: F64) -> F64:
    return np.asarray(np.sum(x, axis=0), dtype=float)


class Likelihood:
    """The fit's likelihood of measured rates ``m`` (N, B) [s-1] under a noise model.

    Parameters
    ----------
    measured
        (N, B) measured rates [s-1]; NaN: not measured.
    sigma
        (N, B) their standard deviations [s-1] (Gaussian; entries not above 0 or not finite
        are not used), or a :class:`PoissonNoise` (module doc; Gaussian where it gives a
        sigma).
    """

    def __init__(self, measured: F64, sigma: F64 | PoissonNoise) -> None:
        m = np.asarray(measured, dtype=float)
        if isinstance(sigma, PoissonNoise):
            t = np.broadcast_to(np.asarray(sigma.exposure_s, dtype=float), m.shape)
            b = np.broadcast_to(np.asarray(sigma.background_e, dtype=float), m.shape)
            given = (
                np.full(m.shape, np.nan)
                if sigma.given_sigma is None
                else np.broadcast_to(np.asarray(sigma.given_sigma, dtype=float), m.shape)
            )
            gauss = np.isfinite(given) & (given > 0)
            pois = ~gauss & np.isfinite(t) & (t > 0) & np.isfinite(b)
        else:
            given = np.broadcast_to(np.asarray(sigma, dtype=float), m.shape)
            gauss = np.isfinite(given) & (given > 0)
            pois = np.zeros(m.shape, dtype=bool)
            t, b = np.ones(m.shape), np.zeros(m.shape)
        used = np.isfinite(m) & (gauss | pois)
        self.gauss = gauss & used
        self.t = np.where(pois & used, t, 1.0)
        self.b = np.where(pois & used, b, 0.0)
        self.sigma = np.where(self.gauss, given, 1.0)
        self.used = used
        self.m = np.where(used, m, 0.0)

    @property
    def poisson(self) -> bool:
        """Whether any entry follows the Poisson model."""
        return bool(np.any(self.used & ~self.gauss))

    def mask(self, model: F64) -> NDArray[np.bool_]:
        """(N, B) the entries used with this model: measured and modelled."""
        return np.asarray(self.used & np.isfinite(model))

    def without(self, drop: NDArray[np.bool_]) -> Likelihood:
        """The same likelihood with the entries ``drop`` (N, B) left out (outliers)."""
        out = object.__new__(Likelihood)
        out.__dict__.update(self.__dict__)
        out.used = self.used & ~np.asarray(drop, dtype=bool)
        out.gauss = self.gauss & out.used
        return out

    def _electrons(self, mu: F64) -> tuple[F64, F64]:
        """Observed and modelled electrons (n, lambda) of every entry (Poisson)."""
        lam = np.maximum(mu * self.t + self.b, FLOOR_E)
        return self.m * self.t + self.b, lam

    def weights(self, mu: F64) -> F64:
        """(N, B) Fisher weights ``1 / var(m)`` at the model ``mu`` [s2]; 0 where unused."""
        use = self.mask(mu)
        _, lam = self._electrons(np.where(use, mu, 0.0))
        w = np.where(self.gauss, 1.0 / self.sigma**2, self.t**2 / lam)
        return np.where(use, w, 0.0)

    def residuals(self, mu: F64) -> F64:
        """(N, B) signed residuals whose squares sum to the deviance (Gaussian: ``(m - mu) /
        sigma``; Poisson: the deviance residuals, module doc); 0 where unused."""
        use = self.mask(mu)
        mu0 = np.where(use, mu, 0.0)
        n, lam = self._electrons(mu0)
        pos = np.maximum(n, 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            log_term = np.where(pos > 0, pos * np.log(pos / lam), 0.0)
        d = np.maximum(2.0 * (lam - pos + log_term), 0.0)
        r = np.where(self.gauss, (self.m - mu0) / self.sigma, np.sign(n - lam) * np.sqrt(d))
        return np.where(use, r, 0.0)

    def deviance(self, mu: F64) -> F64:
        """(B,) the deviance (Gaussian: chi-square) of each band at the model ``mu``."""
        return _sum(self.residuals(mu) ** 2)

    def _score_terms(self, mu: F64) -> F64:
        """(N, B) ``d(-deviance / 2) / d mu`` of every entry: ``w (m - mu)`` (Gaussian),
        ``(n - lambda) / lambda * T`` (Poisson)."""
        n, lam = self._electrons(mu)
        return np.where(self.gauss, (self.m - mu) / self.sigma**2, (n - lam) / lam * self.t)

    def scales(self, c: F64) -> F64:
        """(B,) per-band scales ``s_j`` of the model ``s_j c`` that minimise the deviance
        (NaN where a band's model is zero wherever it is measured): Fisher scoring, which is
        exact in one step for Gaussian entries (module doc)."""
        use = self.mask(c)
        cc = np.where(use, c, 0.0)
        pois = use & ~self.gauss
        wg = np.where(use & self.gauss, 1.0 / self.sigma**2, 0.0)
        wgcc = _sum(wg * cc * cc)
        tc = _sum(np.where(pois, cc * self.t, 0.0))
        good = (wgcc > 0) | (tc > 0)
        s = np.where(wgcc > 0, _sum(wg * self.m * cc) / np.where(wgcc > 0, wgcc, 1.0), 1.0)
        if not np.any(pois):
            return np.asarray(np.where(good, s, np.nan), dtype=float)
        ratio = _sum(np.where(pois, self.m * self.t, 0.0)) / np.where(tc > 0, tc, 1.0)
        s = np.where(tc > 0, np.where(ratio > 0, ratio, 1e-3), s)  # the Poisson MLE if B = 0
        for _ in range(MAX_SCORING):
            mu = s[None, :] * cc
            score = _sum(np.where(use, self._score_terms(mu) * cc, 0.0))
            info = _sum(self.weights(np.where(use, mu, np.nan)) * cc * cc)
            step = np.where(good & (info > 0), score / np.where(info > 0, info, 1.0), 0.0)
            new = s + step
            new = np.where(np.any(pois, axis=0) & (new <= 0), s / 10, new)
            done = np.all(np.abs(new - s) <= SCORING_TOL * np.abs(new))
            s = new
            if done:
                break
        return np.asarray(np.where(good, s, np.nan), dtype=float)

    def scale_derivative(self, c: F64, dc: F64, s: F64) -> F64:
        """(K, B) derivatives of the closed-form scales in K parameters of the model, whose
        derivatives are ``dc`` (K, N, B): the implicit derivative of the score equation
        ``sum score_t c_t = 0`` (Gaussian: exact; Poisson: with the Fisher information for
        the Hessian of the score, its expectation)."""
        use = self.mask(c)
        cc = np.where(use, c, 0.0)
        d = np.where(use[None], np.nan_to_num(dc), 0.0)
        s0 = np.where(np.isfinite(s), s, 0.0)
        mu = s0[None, :] * cc
        w = self.weights(np.where(use, mu, np.nan))
        wcc = _sum(w * cc * cc)
        score = np.where(use, self._score_terms(mu), 0.0)
        num = np.sum(score * d - w * mu * d, axis=1)
        return np.asarray(np.where(wcc > 0, num / np.where(wcc > 0, wcc, 1.0), 0.0), dtype=float)


__all__ = ["FLOOR_E", "Likelihood", "PoissonNoise"]
