"""The memory and time of a spin-axis search, estimated before any work
(:mod:`speclight.estimate.inputs.cost_limits`).

What grows with the options (``grid_deg``, ``n_phases``) and the inputs (epochs ``T``, bands
``B``, the map's phase angles ``P`` and rolls ``R``):

* the **spin-frame map** (:func:`.spin_axis_lookup.spin_frame_map`): ``n_polar x n_az`` cells
  (``n_az`` a multiple of ``n_phases``) x ``P x R`` geometries x ``B`` float32 values, held
  doubled along the azimuth and built through two more copies (5 copies at the peak), plus
  the map lookup's float64 temporaries of one geometry at a time, :data:`LOOKUP_BYTES_PER_CELL`
  and ``16 B`` per cell; built in :data:`SECONDS_PER_CELL_GEOMETRY` per cell and geometry;
* the **grid pass** (:mod:`.spin_axis_grid`): the misfits (A axes x ``n_phases``, float64, 4
  arrays), the lookup indices of a chunk of axes (:data:`BYTES_PER_AXIS_EPOCH` per axis and
  epoch), the measured curves tiled over the phases and a gathered block (3 x ``T x n_phases
  x B`` float32); :data:`SECONDS_PER_LOOKUP` per axis, phase, epoch and band.

The ranging term (``ranging=True``) adds its own spin-frame map (one geometry, ``2 B``
channels) and doubles the grid pass. Rates measured on the box-wing example (768-direction
map, 4 phase angles x 8 rolls, 300 epochs, 10 bands; BENCHMARKS.md "Estimator limits",
``bench/bench_estimator_limits.py``): 6-10.5 us per cell and geometry; the grid pass's
lookups cost 1.1 ns of CPU each as numpy blocks and 0.36 ns in the compiled loop at load ~10
(BENCHMARKS.md "Spin-axis grid pass", 2026-12-04; they were 4.6-9 ns before that loop and the
matmul weighting). The constants are about the upper ends (the numpy fallback, loaded).
"""

from __future__ import annotations

import numpy as np

from speclight.estimate.inputs.cost_limits import ANNOUNCE_SECONDS, check_cost, duration
from speclight.estimate.spin_axis.spin_axis_core import DEFAULT_AXIS_CHUNK
from speclight.estimate.spin_axis.spin_axis_lookup import cell_deg_for

#: float64 temporaries of the map lookup per spin-frame cell, beside ``16 B`` per band [bytes].
LOOKUP_BYTES_PER_CELL = 40 * 8
#: Lookup indices and weights per axis and epoch of a chunk (``spin_axis.DEFAULT_AXIS_CHUNK``)
#: [bytes].
BYTES_PER_AXIS_EPOCH = 512
#: Building the spin-frame map, per cell and map geometry (phase angle x roll) [s].
SECONDS_PER_CELL_GEOMETRY = 10e-6
#: The grid pass per axis, phase, epoch and band [s].
SECONDS_PER_LOOKUP = 2e-9
#: The default ``n_phases`` (``--phases``), to tell which option made a search large.
DEFAULT_PHASES = 72


def grid_size(grid_deg: float) -> tuple[float, float]:
    """RA and Dec cells of :func:`.spin_axis_core.radec_grid` (without making them)."""
    return float(max(1, round(360.0 / grid_deg))), float(max(1, round(180.0 / grid_deg)))


def _frame_map_cost(nside: int, n_geometries: int, n_phases: int, n_channels: int) -> tuple:
    cell = cell_deg_for(nside)
    m = max(1, int(np.ceil(360.0 / n_phases / cell)))
    n_cells = max(2, int(np.ceil(180.0 / cell))) * float(n_phases) * m
    n_bytes = 5 * 4 * n_cells * n_geometries * n_channels
    n_bytes += n_cells * (LOOKUP_BYTES_PER_CELL + 16 * n_channels)
    return n_bytes, n_cells * n_geometries * SECONDS_PER_CELL_GEOMETRY, n_cells


def search_cost(
    nside: int,
    n_phase_angles: int,
    n_rolls: int,
    grid_deg: float,
    n_phases: int,
    n_epochs: int,
    n_bands: int,
    ranging: bool = False,
) -> tuple[float, float, float, float]:
    """(bytes, seconds) of the spin-frame map(s) and (bytes, seconds) of the grid pass of a
    search (module docstring).

    Parameters
    ----------
    nside
        The map's HEALPix nside.
    n_phase_angles, n_rolls
        The map's phase angles and rolls.
    grid_deg
        The RA/Dec grid step [deg].
    n_phases
        Rotation phases tried per axis.
    n_epochs, n_bands
        Epochs and bands measured.
    ranging
        A range-offset term too.
    """
    n_b = n_bands
    map_bytes, map_s, _ = _frame_map_cost(nside, n_phase_angles * n_rolls, n_phases, n_b)
    if ranging:
        r_bytes, r_s, _ = _frame_map_cost(nside, 1, n_phases, 2 * n_b)
        map_bytes, map_s = map_bytes + r_bytes, map_s + r_s
    n_ra, n_dec = grid_size(grid_deg)
    n_axes = float(n_ra) * n_dec
    grid_bytes = 4 * 8 * n_axes * n_phases
    grid_bytes += BYTES_PER_AXIS_EPOCH * min(n_axes, DEFAULT_AXIS_CHUNK) * n_epochs
    grid_bytes += 3 * 4 * float(n_epochs) * n_phases * n_b
    grid_s = n_axes * n_phases * n_epochs * n_b * SECONDS_PER_LOOKUP * (2 if ranging else 1)
    return map_bytes, map_s, grid_bytes, grid_s


def check_search_cost(
    nside: int,
    n_phase_angles: int,
    n_rolls: int,
    grid_deg: float,
    n_phases: int,
    n_epochs: int,
    n_bands: int,
    ranging: bool = False,
) -> None:
    """Refuse a search that cannot finish; announce one of more than a minute.

    The error names ``n_phases`` where the phases make it large (the search with the default
    72 phases would fit), else ``grid_deg``.

    Parameters
    ----------
    nside
        The map's HEALPix nside.
    n_phase_angles, n_rolls
        The map's phase angles and rolls.
    grid_deg
        The RA/Dec grid step [deg].
    n_phases
        Rotation phases tried per axis.
    n_epochs, n_bands
        Epochs and bands measured.
    ranging
        A range-offset term too.
    """
    import warnings

    args = (nside, n_phase_angles, n_rolls, grid_deg)
    map_b, map_s, grid_b, grid_s = search_cost(*args, n_phases, n_epochs, n_bands, ranging)
    n_ra, n_dec = grid_size(grid_deg)
    what = (
        f"the search of {n_ra:.6g} x {n_dec:.6g} axes x {n_phases} phases x {n_epochs} epochs "
        f"x {n_bands} bands (a spin-frame map of {n_phase_angles} phase angles x {n_rolls} "
        f"rolls at HEALPix nside {nside}{', with the ranging term' if ranging else ''})"
    )
    reduce = "give fewer n_phases or a larger grid_deg (or fewer bands, or a shorter pass)"
    n_bytes, seconds = max(map_b, grid_b), map_s + grid_s
    base = search_cost(*args, min(n_phases, DEFAULT_PHASES), n_epochs, n_bands, ranging)
    phases_alone = max(base[0], base[2]) < n_bytes / 10 or base[1] + base[3] < seconds / 10
    if phases_alone and n_phases > DEFAULT_PHASES:
        check_cost("n_phases", n_phases, what, n_bytes, seconds, reduce)
    else:
        check_cost("grid_deg", grid_deg, what, n_bytes, seconds, reduce)
    if seconds > ANNOUNCE_SECONDS:
        warnings.warn(f"spin-axis: {what}: about {duration(seconds)}", stacklevel=2)


__all__ = ["check_search_cost", "grid_size", "search_cost"]
