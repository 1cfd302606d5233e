"""Magnitudes of the observed rows as a function of the fitted surfaces' BRDF coefficients.

The band reflectance factor of a row (docs/fit.md; the pipeline's ``reflectance_factor``,
the band count rate over that of a 1 m2 sr-1 grey target under the same Sun, atmosphere and
instrument) is the sum of every surface's share. For grey fitted surfaces a surface's share
is ``sum_records weight_m2 f(cos...) cos_i`` (:mod:`.surface_records`), the same in every
band; the other materials' share (measured tables, Lambertian parts) does not change in the
fit. So with ``RF0`` and ``m0`` the simulated reflectance factor and AB magnitude at the
start::

    RF(theta) = RF0 - F(theta0) + F(theta),    m(theta) = m0 - 2.5 log10(RF(theta) / RF0)

with ``F`` the fitted surfaces' share. This is exact (AB magnitude and count rate scale
alike when the spectrum's shape does not change: grey surfaces, grey Earthshine), and costs
one evaluation of the BRDFs on the records per step.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.surface_fit.surface_parameters import FreeSurface
from speclight.estimate.surface_fit.surface_records import SurfaceRecords
from speclight.target.brdf_fit.form_coefficients import evaluate

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]
#: Least reflectance factor of a row relative to its start (a fit that switches every
#: surface off gives 25 mag fainter, not a log of 0).
FLOOR = 1e-10


class SurfaceModel:
    """``model.magnitude(u)``: every row's AB magnitude [mag] for the fit's variables ``u``.

    Parameters
    ----------
    surfaces
        The fitted surfaces; ``u`` is their variables one after the other.
    records
        Their records, ``epoch`` an index into ``n_epochs`` epochs.
    row_epoch
        (R,) each row's epoch index.
    magnitude0, reflectance_factor0
        (R,) the simulated AB magnitude [mag] and band reflectance factor [m2 sr-1] of each
        row at the start.
    n_epochs
        The number of epochs the indices run over.
    """

    def __init__(
        self,
        surfaces: list[FreeSurface],
        records: SurfaceRecords,
        row_epoch: I64,
        magnitude0: F64,
        reflectance_factor0: F64,
        n_epochs: int,
    ) -> None:
        self.surfaces = surfaces
        self.n_epochs = n_epochs
        self.row_epoch = row_epoch
        self.magnitude0 = magnitude0
        self.rf0 = reflectance_factor0
        self.sizes = [len(s.free) for s in surfaces]
        self._records = []
        for k in range(len(surfaces)):
            sel = records.surface == k
            self._records.append(
                (
                    records.epoch[sel],
                    records.cos_i[sel],
                    records.cos_o[sel],
                    records.cos_h[sel],
                    records.cos_d[sel],
                    records.weight_m2[sel] * records.cos_i[sel],
                )
            )
        self.u0 = np.concatenate([s.start_vector() for s in surfaces])
        self.rf_fixed = self.rf0 - self.free_share(self.u0)[row_epoch]

    def split(self, u: F64) -> list[F64]:
        """``u`` cut into each surface's variables."""
        return np.split(np.asarray(u, dtype=float), np.cumsum(self.sizes)[:-1])

    def surface_share(self, k: int, u_k: F64) -> F64:
        """Surface k's share of the reflectance factor per epoch (n_epochs,) [m2 sr-1]."""
        epoch, ci, co, ch, cd, w = self._records[k]
        s = self.surfaces[k]
        f = evaluate(s.bsdf, s.coefficients(u_k), ci, co, ch, cd)
        return np.asarray(np.bincount(epoch, weights=w * f, minlength=self.n_epochs), dtype=float)

    def free_share(self, u: F64) -> F64:
        """The fitted surfaces' share per epoch (n_epochs,) [m2 sr-1]."""
        total = np.zeros(self.n_epochs)
        for k, u_k in enumerate(self.split(u)):
            total += self.surface_share(k, u_k)
        return total

    def magnitude(self, u: F64) -> F64:
        """(R,) AB magnitude of every row [mag] (module doc)."""
        rf = self.rf_fixed + self.free_share(u)[self.row_epoch]
        return np.asarray(
            self.magnitude0 - 2.5 * np.log10(np.maximum(rf, FLOOR * self.rf0) / self.rf0)
        )

    def surface_fractions(self, u: F64) -> F64:
        """(surfaces + 1, R): each fitted surface's and the fixed materials' fraction of
        every row's reflectance factor [1]."""
        parts = [self.surface_share(k, u_k)[self.row_epoch] for k, u_k in enumerate(self.split(u))]
        parts.append(np.maximum(self.rf_fixed, 0.0))
        stack = np.array(parts)
        return np.asarray(stack / np.maximum(stack.sum(axis=0), 1e-300))
