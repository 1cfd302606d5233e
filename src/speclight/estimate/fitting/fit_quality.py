"""What the fit says about its data: outliers left out, and a misfit far above the noise.

**Outliers** (issue 25: a cosmic ray or a glint the model lacks widened the fit's sigma 5.6x
and nothing said so). After a fit, every measurement's normalised residual ``r`` (the
deviance residual of :class:`~speclight.estimate.fitting.noise_model.Likelihood`: ``(m - mu)
/ sigma`` with Gaussian sigmas) is compared with :data:`CLIP_SIGMA` times the residuals'
robust spread, ``max(1, 1.4826 median |r|)`` (the normalised median absolute deviation about
the model, Rousseeuw & Croux 1993, doi:10.1080/01621459.1993.10476408; at least 1 so that
well-fitted data are clipped at ``CLIP_SIGMA`` noise sigmas, and a model that misfits
everywhere does not lose its data). Those beyond are left out and the fit is repeated, at
most :data:`MAX_ROUNDS` times; the fit says how many were left out and where. For Gaussian
noise, 5 sigma leaves out a correct measurement with probability 5.7e-7: one in 1.7 million.

**Misfit.** The deviance (chi-square) per degree of freedom is about 1 when the model and the
noise model are right; above ``1 + MISFIT_SIGMAS sqrt(2 / dof)`` (the chi-square's own spread,
:data:`MISFIT_SIGMAS` of them) the fit says so: the standard deviations are then inflated by
``sqrt(chi2 / dof)`` (:mod:`.fit`), and the model (shape, attitude, roughness held) or the
noise (sigmas too small) is wrong.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.fitting.fit import ScaleFit, scale_fit
from speclight.estimate.fitting.noise_model import Likelihood

F64 = NDArray[np.float64]

#: Measurements farther than this many robust sigmas from the fit are left out.
CLIP_SIGMA = 5.0
#: Fits repeated without the outliers found, at most.
MAX_ROUNDS = 3
#: A chi-square per degree of freedom this many of its own standard deviations above 1 is
#: reported as a misfit.
MISFIT_SIGMAS = 5.0
#: Normal standard deviation per median absolute deviation: 1 / Phi^-1(3/4).
MAD_TO_SIGMA = 1.482602218505602
#: Outlier positions named in a message, at most.
SHOWN = 5


def outlier_mask(likelihood: Likelihood, mu: F64, clip_sigma: float | None) -> NDArray[np.bool_]:
    """(N, B) measurements more than ``clip_sigma`` robust sigmas from the model ``mu``
    [s-1] (module doc); none when ``clip_sigma`` is None."""
    use = likelihood.mask(mu)
    if clip_sigma is None or not np.any(use):
        return np.zeros(use.shape, dtype=bool)
    r = np.abs(likelihood.residuals(mu))
    spread = max(1.0, MAD_TO_SIGMA * float(np.median(r[use])))
    return np.asarray(use & (r > clip_sigma * spread))


def outlier_text(drop: NDArray[np.bool_], time_utc: NDArray, bands: list[str], clip: float) -> str:
    """The notice of the measurements ``drop`` (N, B) left out (empty when none)."""
    rows, cols = np.nonzero(drop)
    if rows.size == 0:
        return ""
    where = ", ".join(
        f"{bands[j]} at {np.datetime_as_string(time_utc[i], unit='s')}"
        for i, j in zip(rows[:SHOWN], cols[:SHOWN], strict=True)
    )
    more = f" and {rows.size - SHOWN} more" if rows.size > SHOWN else ""
    return (
        f"{rows.size} measurement(s) more than {clip:g} robust sigmas from the fit were left out "
        f"as outliers ({where}{more}); clip_sigma=None keeps them"
    )


def reduced_chi2(deviance: float, n_data: int, n_par: int) -> float:
    """The deviance (chi-square) per degree of freedom."""
    return float(deviance) / max(n_data - n_par, 1)


def misfit_text(deviance: float, n_data: int, n_par: int) -> str:
    """The notice of a chi-square far above its degrees of freedom (module doc), or ""."""
    dof = max(n_data - n_par, 1)
    red = reduced_chi2(deviance, n_data, n_par)
    if red <= 1 + MISFIT_SIGMAS * np.sqrt(2 / dof):
        return ""
    return (
        f"the model misfits the data: chi-square per degree of freedom {red:.3g} (expected "
        f"1 +- {np.sqrt(2 / dof):.2g}); the standard deviations are inflated by "
        f"{np.sqrt(red):.3g}; the model (shape, attitude, fixed parameters) or the noise "
        "(sigmas too small) is not right"
    )


def clipped_scales(
    likelihood: Likelihood, model: F64, clip_sigma: float | None
) -> tuple[ScaleFit, NDArray[np.bool_]]:
    """The closed-form band scales (:func:`.fit.scale_fit`) of the model ``model`` (N, B)
    [s-1], refitted without the outliers (module doc) until none is left, at most
    :data:`MAX_ROUNDS` times; and the (N, B) outliers left out."""
    drop = np.zeros(likelihood.m.shape, dtype=bool)
    fit = scale_fit(likelihood, model)
    for _ in range(MAX_ROUNDS):
        s = np.where(np.isfinite(fit.scale), fit.scale, 0.0)
        new = outlier_mask(likelihood.without(drop), s[None, :] * model, clip_sigma)
        if not np.any(new):
            break
        drop |= new
        fit = scale_fit(likelihood.without(drop), model)
    return fit, drop


__all__ = [
    "CLIP_SIGMA",
    "MAX_ROUNDS",
    "MISFIT_SIGMAS",
    "clipped_scales",
    "misfit_text",
    "outlier_mask",
    "outlier_text",
    "reduced_chi2",
]
