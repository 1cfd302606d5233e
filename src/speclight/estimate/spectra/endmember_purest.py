"""``purest``: endmembers from the purest epochs, not the brightest.

A band reflectance factor is a non-negative mixture ``x = sum_k g_k s_k``; its brightness
``sum_j x_j`` says how much is seen, its shape ``x / sum_j x_j`` what. ATGP on ``x`` itself
takes the sample of largest norm first, a glint, whatever its mixture (issue 25: on the
four-material cube 25 deg from the true spectra where the purest epochs were 0-7 deg). Here:

1. samples too noisy to have a shape are left out: signal-to-noise ``|x| / |sigma|`` below
   ``PUREST_MIN_SNR`` (without a noise estimate: a norm below ``PUREST_MIN_BRIGHTNESS`` of the
   90th percentile of the norms);
2. every sample is normalised to unit band sum, which puts the pure samples at the vertices
   of the simplex of shapes (Keshava & Mustard 2002, doi:10.1109/79.974727), and ATGP
   (Ren & Chang 2003, doi:10.1109/TAES.2003.1261119) runs on the shapes;
3. with a noise estimate, each chosen shape is replaced by the inverse-variance mean of the
   shapes within the noise of it (mean squared normalised distance below
   ``PUREST_CLUSTER_CHI2``), times their median brightness: a pure face seen over several
   epochs gives a signature with less noise than one epoch.

It says when the data may hold fewer pure epochs than endmembers asked: a signature that
rests on fewer than ``PUREST_MIN_EPOCHS`` epochs within the noise of it.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]
#: Least signal-to-noise ratio ``|x| / |sigma|`` of a sample whose shape is used.
PUREST_MIN_SNR = 10.0
#: Without noise estimates: least norm, as a fraction of the 90th percentile of the norms.
PUREST_MIN_BRIGHTNESS = 0.1
#: A sample belongs to a chosen shape when its mean squared normalised distance is below this.
PUREST_CLUSTER_CHI2 = 2.0
#: Fewest epochs a signature should rest on before it is called supported.
PUREST_MIN_EPOCHS = 3


def purest(
    x: F64, k: int, sigma: F64 | None, atgp: object
) -> tuple[NDArray[np.intp], F64, tuple[str, ...]]:
    """Rows chosen, signatures (K, B) [unit of ``x``] and notes (module doc).

    ``x`` (N, B) finite samples, ``sigma`` (N, B) their noise or None, ``atgp`` the ATGP
    of :mod:`.endmembers` (``atgp(samples, k) -> rows``).
    """
    total = x.sum(axis=1)
    norm = np.linalg.norm(x, axis=1)
    if sigma is not None:
        keep = (norm / np.sqrt(np.sum(sigma**2, axis=1)) >= PUREST_MIN_SNR) & (total > 0)
    else:
        keep = (norm >= PUREST_MIN_BRIGHTNESS * np.percentile(norm, 90)) & (total > 0)
    rows = np.flatnonzero(keep)
    if rows.size < k:
        rows = np.flatnonzero(total > 0)
    shapes = x / total[:, None]
    chosen = rows[atgp(shapes[rows], k)]  # type: ignore[operator]
    if sigma is None:
        return chosen, x[chosen].copy(), ()
    shape_sigma = sigma / np.abs(total)[:, None]
    signatures = np.empty((k, x.shape[1]))
    support = np.empty(k, dtype=np.intp)
    for j, i in enumerate(chosen):
        d2 = np.mean(
            (shapes[rows] - shapes[i]) ** 2 / (shape_sigma[rows] ** 2 + shape_sigma[i] ** 2), 1
        )
        member = rows[d2 < PUREST_CLUSTER_CHI2]
        w = 1.0 / shape_sigma[member] ** 2
        signatures[j] = (shapes[member] * w).sum(axis=0) / w.sum(axis=0) * np.median(total[member])
        support[j] = member.size
    return chosen, signatures, _notes(support)


def _notes(support: NDArray[np.intp]) -> tuple[str, ...]:
    return tuple(
        f"endmember {j + 1} rests on {n} epoch(s) only: it may be a mixture (fewer pure "
        "epochs than endmembers asked)"
        for j, n in enumerate(support)
        if n < PUREST_MIN_EPOCHS
    )
