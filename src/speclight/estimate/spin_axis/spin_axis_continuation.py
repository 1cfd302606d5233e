"""Graduated optimisation (continuation) of the spin-axis refinement (issue 15 item 2).

The gradient refinement (:mod:`.spin_axis_refine`, L-BFGS-B) is followed from a smoothed
misfit to the real one: each stage starts where the previous one ended, the last stage is
the real misfit. Two ways of smoothing, measured in ``bench/bench_spin_continuation.py``:

* **a coarser map** (:func:`coarsen_map`): the HEALPix directions degraded to a lower
  ``nside`` (each coarse pixel the mean of its children; the map is RING-ordered, the
  children of NESTED pixel ``k`` are ``4k .. 4k + 3``) and the rolls to fewer (a circular
  ``[1/4, 1/2, 1/4]`` filter, then every other roll, so that roll ``k`` of the coarse map
  is at ``k`` times its step, as :func:`speclight.maps.map_lookup.roll_weights` wants);
  With ranging returns the offsets' map is coarsened in the same way.
* **light curves smoothed in time** (:class:`SmoothedMisfit`): a Gaussian of ``sigma_s``
  seconds over the epochs applied to the residuals (the normalised measured and predicted
  curves alike; it is linear, so the Jacobian is smoothed the same way).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.estimate.spin_axis.spin_axis_gradient import SpinMisfit
from speclight.maps.map_geometry import healpix_directions
from speclight.maps.map_lookup import ReflectivityMap

F64 = NDArray[np.float64]


def coarsen_map(bmap: ReflectivityMap, nside: int | None, n_rolls: int | None) -> ReflectivityMap:
    """``bmap`` degraded to HEALPix ``nside`` and ``n_rolls`` rolls (None: unchanged).

    ``nside`` a power of two no larger than the map's; ``n_rolls`` the map's roll count
    divided by a power of two (module docstring). Range data are dropped (not needed here).
    """
    from astropy_healpix import healpy as hp

    table = np.asarray(bmap.intensity_W_sr_nm, dtype=np.float64)
    header = bmap.header
    n0 = header.nside
    directions = bmap.direction_body
    if nside is not None and nside != n0:
        if nside > n0 or n0 % nside or (n0 // nside) & (n0 // nside - 1):
            raise ValueError(f"nside {nside} is not the map's {n0} divided by a power of two")
        nest = hp.ring2nest(n0, np.arange(12 * n0 * n0))
        parent = hp.nest2ring(nside, nest // (n0 // nside) ** 2)
        coarse = np.zeros((12 * nside * nside, *table.shape[1:]))
        np.add.at(coarse, parent, table)
        table = coarse / (n0 // nside) ** 2
        directions = healpix_directions(nside)
        header = dataclasses.replace(header, nside=int(nside))
    r0 = table.shape[2]
    if n_rolls is not None and n_rolls != r0:
        if n_rolls > r0 or r0 % n_rolls or (r0 // n_rolls) & (r0 // n_rolls - 1):
            raise ValueError(f"{n_rolls} rolls is not the map's {r0} divided by a power of two")
        while table.shape[2] > n_rolls:
            table = 0.5 * table + 0.25 * (np.roll(table, 1, axis=2) + np.roll(table, -1, axis=2))
            table = table[:, :, ::2]
        header = dataclasses.replace(header, roll_deg=np.arange(n_rolls) * 360.0 / n_rolls)
    return ReflectivityMap(
        header=header,
        direction_body=directions,
        intensity_W_sr_nm=table.astype(np.float32),
    )


def gaussian_smoother(t_s: ArrayLike, sigma_s: float) -> F64:
    """(T, T) rows of Gaussian weights ``exp(-(t_i - t_j)^2 / (2 sigma^2))`` summing to 1."""
    t = np.asarray(t_s, dtype=float)
    w = np.exp(-0.5 * ((t[:, None] - t[None, :]) / sigma_s) ** 2)
    return w / w.sum(axis=1, keepdims=True)


@dataclass(frozen=True)
class SmoothedMisfit(SpinMisfit):
    """:class:`.SpinMisfit` with its light-curve residuals smoothed in time by ``smoother``
    (T, T) (None: not smoothed); the ranging residuals are left as they are."""

    smoother: F64 | None = None

    def residuals(self, x: ArrayLike, jacobian: bool = True) -> tuple[F64, F64 | None]:
        r, jac = super().residuals(x, jacobian)
        s = self.smoother
        if s is None or not np.all(np.isfinite(r)):
            return r, jac
        n_t, n_b = self.y.shape
        m = n_t * n_b
        r = np.concatenate([(s @ r[:m].reshape(n_t, n_b)).ravel(), r[m:]])
        if jac is not None:
            k = jac.shape[1]
            head = np.einsum("ij,jbk->ibk", s, jac[:m].reshape(n_t, n_b, k)).reshape(m, k)
            jac = np.concatenate([head, jac[m:]])
        return r, jac


@dataclass(frozen=True)
class Stage:
    """One stage of the continuation: the map at ``nside`` with ``n_rolls`` rolls (None:
    the map's own) and the light curves smoothed over ``sigma_s`` seconds (0: not)."""

    nside: int | None = None
    n_rolls: int | None = None
    sigma_s: float = 0.0


def stage_model(model: SpinMisfit, stage: Stage) -> SpinMisfit:
    """``model`` with its map coarsened and its residuals smoothed as ``stage`` says (the
    same parameters ``x``: the stages follow one another from where the last ended)."""
    fields = {f.name: getattr(model, f.name) for f in dataclasses.fields(SpinMisfit)}
    fields["bmap"] = coarsen_map(model.bmap, stage.nside, stage.n_rolls)
    rg = model.ranging
    if rg is not None and rg.weight:  # the offsets' map (coaxial: one roll) coarsened alike
        fields["ranging"] = dataclasses.replace(rg, bmap=coarsen_map(rg.bmap, stage.nside, None))
    if stage.sigma_s > 0:
        return SmoothedMisfit(**fields, smoother=gaussian_smoother(model.geo.t_s, stage.sigma_s))
    return SpinMisfit(**fields)


def continuation_stages(nside: int) -> list[Stage]:
    """The stages of ``--refine gradient-continuation`` for a map of ``nside``: the
    directions at ``nside`` 2, 4, ... up to ``nside / 2`` (none for ``nside <= 2``), the
    rolls and phase angles the map's own, no time smoothing (what
    ``bench/bench_spin_continuation.py`` measured best: docs/spin-axis.md)."""
    out, n = [], 2
    while n < nside:
        out.append(Stage(n, None, 0.0))
        n *= 2
    return out
