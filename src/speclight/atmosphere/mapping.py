"""Map transmission spectra known at a few airmasses to every line of sight.

For extinction by scattering (Rayleigh, aerosol) and by continuum absorption (ozone
Chappuis band), the optical depth of a slant path is the vertical optical depth times the
airmass, so ``ln T`` is linear in the airmass (Beer-Lambert-Bouguer law):
``T(m) = T(1) ** m``. Band-averaged transmission in saturated molecular bands (O2 A-band,
water at 940 nm) grows more slowly than linearly in optical depth (curve of growth), so
models that supply several airmass nodes are interpolated linearly in ``ln T`` between
nodes, which is exact for the continuum and follows the curve of growth piecewise.
References: K. N. Liou, *An Introduction to Atmospheric Radiation*, 2nd ed. (Academic
Press, 2002), sec. 1.4 (Beer-Bouguer-Lambert law) and sec. 4.3 (band transmittance);
R. M. Goody and Y. L. Yung, *Atmospheric Radiation*, 2nd ed. (OUP, 1989), ch. 4 (curve of
growth).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

#: Floor of the transmission before taking logs (a fully opaque band) [1].
T_FLOOR = 1e-12


def log_transmission(t: NDArray[np.float64]) -> NDArray[np.float64]:
    """Natural log of a transmission, floored at :data:`T_FLOOR` so opaque bands stay finite."""
    return np.log(np.clip(t, T_FLOOR, 1.0))


def interpolate_in_airmass(
    nodes: NDArray[np.float64], log_t: NDArray[np.float64], airmass_: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Transmission (N, L) at airmasses ``airmass_`` (N,) from ``ln T`` (K, L) at ``nodes`` (K,).

    One node: Beer-Lambert scaling ``ln T(m) = ln T(m0) * m / m0``. Several nodes: linear in
    ``ln T`` between nodes and linear extrapolation with the end segments (the local
    Beer-Lambert slope), capped at T = 1. NaN airmass gives a NaN row.
    """
    nodes = np.asarray(nodes, dtype=np.float64)
    m = np.asarray(airmass_, dtype=np.float64)
    out = np.full((m.size, log_t.shape[1]), np.nan)
    ok = np.isfinite(m)
    mm = m[ok]
    if nodes.size == 1:
        lt = log_t[0][None, :] * (mm / nodes[0])[:, None]
    else:
        k = np.clip(np.searchsorted(nodes, mm, side="right") - 1, 0, nodes.size - 2)
        w = ((mm - nodes[k]) / (nodes[k + 1] - nodes[k]))[:, None]
        lt = (1.0 - w) * log_t[k] + w * log_t[k + 1]
    out[ok] = np.exp(np.minimum(lt, 0.0))
    out[ok] = np.where(out[ok] <= T_FLOOR * 1.0000001, 0.0, out[ok])
    return out
