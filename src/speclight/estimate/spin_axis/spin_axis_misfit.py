"""The misfit of one spin-axis candidate with the map's own interpolation (no spin-frame
grid): what the refinements of :mod:`.spin_axis_refine` minimise (definitions in
:mod:`.spin_axis_core`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.attitude.quaternion import quat_to_matrix
from speclight.attitude.spin import spin_attitude
from speclight.estimate.spin_axis.spin_axis_grid import misfit_from_sums
from speclight.estimate.spin_axis.spin_axis_lookup import EpochGeometry
from speclight.maps.map_lookup import ReflectivityMap

if TYPE_CHECKING:
    from speclight.estimate.spin_axis.spin_axis_ranging import RangingTerm

F64 = NDArray[np.float64]


def exact_misfit(
    bmap: ReflectivityMap,
    geo: EpochGeometry,
    y: F64,
    spin_body_axis: ArrayLike | None,
    ra_deg: float,
    dec_deg: float,
    phase_deg: float,
    ranging: RangingTerm | None = None,
) -> float:
    """The misfit of one candidate with the map's own interpolation (no spin-frame grid).

    Parameters
    ----------
    bmap
        The band map (:func:`.spin_axis_lookup.load_band_map`).
    geo
        Sun and observer directions and times of the epochs.
    y
        Measured band light curves (T, B).
    spin_body_axis
        The spin axis in the body frame (3,), or None (+z).
    ra_deg, dec_deg, phase_deg
        The candidate: the axis (GCRS) and the rotation phase at the scenario start [deg].
    ranging
        The range-offset term, or None.
    """
    if not -90.0 <= dec_deg <= 90.0:
        return float("inf")
    q = spin_attitude(geo.t_s, ra_deg, dec_deg, geo.period_s, phase_deg, spin_body_axis)
    r = quat_to_matrix(q)
    s = np.einsum("tji,tj->ti", r, geo.sun_gcrs)
    o = np.einsum("tji,tj->ti", r, geo.observer_gcrs)
    p = bmap.intensity_1au(s, o)
    yn = y / np.mean(y, axis=0)
    if not np.all(np.isfinite(p)):
        return float("inf")
    s1, s2, sy = p.sum(0)[:, None], (p**2).sum(0)[:, None], (p * yn).sum(0)[:, None]
    e = float(misfit_from_sums(s1, s2, sy, np.sum(yn**2, axis=0), y.shape[0])[0])
    if ranging is not None and ranging.weight:
        from speclight.estimate.spin_axis.spin_axis_ranging import exact_term

        e += ranging.weight * exact_term(ranging, o)
    return e
