"""Bins of ``speclight fit --bin-s``: measurements and model averaged over the same entries.

A bin's mean rate is compared with the mean of the model over the **same** epochs and bands,
each simulated at its own epoch. Since the model is linear in the band scales,
``mean_t(s c_t) = s mean_t(c_t)``, so binning changes the weights of the fit, not what it
estimates, however fast the light changes within a bin.

(Before, the model was simulated once at each bin's mean epoch. The mean of a light curve
over a bin is not its value at the mean epoch where it curves (range, phase angle, a
spinning body's glints), and the mean epoch counted the epochs without a measurement too, so
that it could fall where the target is dim or unseen: a 100 s bin over a pass that entered
the Earth's penumbra gave albedos of 1e11.)

The bins are those of :func:`speclight.estimate.bin_light_curve`: ``bin_s`` seconds from the
first epoch; a bin's epoch is the mean of its epochs that hold a used entry; bins without
one are left out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]


@dataclass(frozen=True)
class EpochBins:
    """Averaging of (N, B) entries into bins of epochs.

    Attributes
    ----------
    slot
        (N,) the bin of each epoch (-1: none of its entries used).
    use
        (N, B) the entries averaged.
    count
        (n_bins, B) the entries averaged per bin and band.
    time_utc
        (n_bins,) each bin's epoch: the mean of its epochs with a used entry.
    """

    slot: NDArray[np.int64]
    use: NDArray[np.bool_]
    count: F64
    time_utc: NDArray[np.datetime64]

    @classmethod
    def of(cls, time_utc: NDArray[np.datetime64], bin_s: float, use: NDArray) -> EpochBins:
        """Bins of ``bin_s`` seconds [s] over ``time_utc`` (N,) of the entries ``use`` (N, B)."""
        t = np.asarray(time_utc, dtype="datetime64[ns]")
        use = np.asarray(use, dtype=bool)
        dt = (t - t[0]) / np.timedelta64(1, "s")
        key = np.floor(dt / bin_s).astype(np.int64)
        any_used = use.any(axis=1)
        kept, inverse = np.unique(key[any_used], return_inverse=True)
        slot = np.full(t.size, -1, dtype=np.int64)
        slot[any_used] = inverse
        count = np.zeros((kept.size, use.shape[1]))
        np.add.at(count, slot[any_used], use[any_used].astype(float))
        offset_ns = (t[any_used] - t[0]).astype(np.int64).astype(float)
        total = np.zeros(kept.size)
        np.add.at(total, slot[any_used], offset_ns)
        n_epochs = np.bincount(slot[any_used], minlength=kept.size)
        times = t[0] + np.rint(total / n_epochs).astype("timedelta64[ns]")
        return cls(slot, use, count, times)

    @property
    def n_bins(self) -> int:
        """Number of bins."""
        return int(self.count.shape[0])

    def _sum(self, values: F64, axis: int) -> F64:
        v = np.moveaxis(np.asarray(values, dtype=float), axis, 0)
        keep = self.slot >= 0
        n, b = self.use.shape
        use = self.use.reshape((n,) + (1,) * (v.ndim - 2) + (b,))  # the bands last
        out = np.zeros((self.n_bins, *v.shape[1:]))
        np.add.at(out, self.slot[keep], np.where(use, v, 0.0)[keep])
        return out

    def _per_bin(self, total: F64, axis: int, ndim: int) -> F64:
        count = self.count.reshape((self.n_bins,) + (1,) * (ndim - 2) + (self.count.shape[1],))
        with np.errstate(invalid="ignore", divide="ignore"):
            out = np.where(count > 0, total / np.where(count > 0, count, 1.0), np.nan)
        return np.moveaxis(out, 0, axis)

    def mean(self, values: F64, axis: int = 0) -> F64:
        """The mean over each bin's used entries of ``values`` whose epoch axis is ``axis``
        and band axis the last ((N, B), or (K, N, B) with ``axis=1``); NaN where a bin has
        no used entry in a band, or a used entry is NaN."""
        v = np.asarray(values, dtype=float)
        return self._per_bin(self._sum(v, axis), axis, v.ndim)

    def sigma(self, sigma: F64) -> F64:
        """The standard deviation of a bin's mean of independent entries of ``sigma`` (N, B):
        ``sqrt(sum sigma^2) / n``."""
        return np.sqrt(self.mean(np.asarray(sigma, dtype=float) ** 2) / self.count_or_nan)

    @property
    def count_or_nan(self) -> F64:
        """``count`` with NaN for 0."""
        return np.where(self.count > 0, self.count, np.nan)


__all__ = ["EpochBins"]
