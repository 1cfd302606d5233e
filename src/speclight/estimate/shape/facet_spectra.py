"""Per-band facet factors: the EGI's colours, with the geometry of a grey fit held.

With the rotation state and the facet areas ``a`` of the grey fit (the mean over bands),
each band ``b``'s factors ``y_b(t)`` are linear in the facets' band ratios ``r_kb``:
``y_b = S (a * r_b)`` with ``S`` (N, K) the law's per-facet brightness. The ratios are
found by Tikhonov-regularised least squares towards grey (``r = 1``; Tikhonov & Arsenin
1977), ``min |W (y_b - S diag(a) r)|^2 + mu |r - 1|^2`` with ``mu`` =
:data:`RIDGE` times the mean diagonal of the normal matrix (a facet the data do not see
stays grey). The result is ``a_k r_kb`` [the brightness unit times sr]: a facet's area
times its albedo in each band, the spectrum of each facet.

Per-facet unmixing (:func:`facet_materials`): each facet's band spectrum split into the
scenario's materials by non-negative least squares against their band signatures
(:func:`speclight.estimate.spectra.endmember_spectra.endmembers_from_scenario`, the unmixing of
``speclight unmix``, :func:`speclight.estimate.spectra.unmixing.unmix`): with the Lambert law the
band spectrum is the facet's area times its band albedos, so the result is each
material's area on the facet [m2].
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.estimate.shape.convex_fit import ConvexSolution
from speclight.estimate.shape.convex_model import N_ROTATION, ConvexModel

if TYPE_CHECKING:
    from speclight.estimate.inputs.band_responses import BandResponses
    from speclight.scenario import LoadedScenario

F64 = NDArray[np.float64]
RIDGE = 0.01


def facet_design(model: ConvexModel, sol: ConvexSolution) -> F64:
    """(N, K) each facet's brightness per unit area at the solution's rotation."""
    k = len(model.normals)
    cols = np.empty((model.data.n_points, k))
    theta = sol.theta.copy()
    theta[N_ROTATION:] = 0.0
    _, jac = model.brightness(theta, jacobian=True)
    assert jac is not None
    cols[:] = jac[:, N_ROTATION:]  # dL/dg_k at g = 0 is the facet's S
    return cols


def facet_band_factors(
    model: ConvexModel, sol: ConvexSolution, band_factor: F64, band_sigma: F64 | None
) -> F64:
    """(K, B) ``a_k r_kb`` (module doc)."""
    s = facet_design(model, sol) * sol.areas[None, :]
    out = np.empty((len(model.normals), band_factor.shape[1]))
    for b in range(band_factor.shape[1]):
        y = band_factor[:, b]
        w = 1.0 / (band_sigma[:, b] if band_sigma is not None else model.data.sigma)
        ok = np.isfinite(y) & np.isfinite(w)
        a = s[ok] * w[ok, None]
        ata = a.T @ a
        mu = RIDGE * float(np.mean(np.diag(ata)))
        rhs = a.T @ (y[ok] * w[ok]) + mu * np.ones(ata.shape[0])
        r = np.linalg.solve(ata + mu * np.eye(ata.shape[0]), rhs)
        out[:, b] = sol.areas * np.clip(r, 0.0, None)
    return out


def facet_materials(
    facet_band_area: F64, loaded: LoadedScenario, bands: BandResponses
) -> tuple[list[str], F64] | None:
    """Material names (M,) and each facet's area of each material (K, M) (module doc).

    None, with a warning, where the materials' band signatures are linearly dependent in
    these bands (e.g. two grey materials of different albedo seen in few bands): their shares
    are then not determined, and the facet spectra stand alone.
    """
    from speclight.estimate.spectra.endmember_spectra import endmembers_from_scenario
    from speclight.estimate.spectra.unmixing import unmix

    ends = endmembers_from_scenario(loaded, bands)
    if len(ends.names) > facet_band_area.shape[1]:
        raise InputError(
            f"{len(ends.names)} distinct materials cannot be unmixed from "
            f"{facet_band_area.shape[1]} bands (give at least as many bands as materials)",
            field="bands",
        )
    rank = int(np.linalg.matrix_rank(np.asarray(ends.signatures, dtype=float)))
    if rank < len(ends.names):
        warnings.warn(
            f"facet materials not unmixed: the band signatures of the scenario's "
            f"{len(ends.names)} materials ({', '.join(ends.names)}) are linearly dependent in "
            f"these {facet_band_area.shape[1]} bands (rank {rank}), so their shares are not "
            "determined; the facet spectra (facet_band_area) are written without them",
            stacklevel=2,
        )
        return None
    return ends.names, unmix(facet_band_area, ends.signatures, "nnls").abundance
