"""The range-offset bins of laser return histograms: the one place that chooses them."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from speclight.target.parts import Target

F64 = NDArray[np.float64]
#: Bins over the single-bounce span (twice as many in multi-bounce mode).
RANGE_BINS = 200


def range_bin_edges_m(
    target: Target,
    com_body_m: F64,
    n_bins: int = RANGE_BINS,
    multibounce: bool = False,
) -> F64:
    """Uniform range-offset bin edges [m] for a target's returns.

    One bounce from any point of the target lies within ``+-r_max`` of the centre of mass,
    ``r_max`` = its distance to the bounding sphere's far side (times 1.001). Interreflections
    arrive later: with ``multibounce`` the bins cover ``[-r_max, 3 r_max]`` with ``2 n_bins``
    bins (the same width), the last bin collecting the (rare) longer paths.
    """
    centre, radius = target.bounding_sphere()
    r_max = float(np.linalg.norm(centre - np.asarray(com_body_m, dtype=float)) + radius) * 1.001
    if multibounce:
        return np.linspace(-r_max, 3.0 * r_max, 2 * int(n_bins) + 1)
    return np.linspace(-r_max, r_max, int(n_bins) + 1)
