"""Observed positions of many objects in one table: a trajectory per object, from its own rows.

Rows of two satellites seen 10 s apart must not make one trajectory (a straight line from
one to the other). Each object gets the trajectory of
:func:`~speclight.orbit.observed_position.observed_trajectory` through its own rows only.
The geometry stage asks a trajectory for positions at times alone, so the objects are
grouped into *layers*: within a layer the objects' time windows (first to last emission,
widened by ``margin_s`` on both sides) do not overlap, and a layer's trajectory answers a
time with the one object whose window holds it. Every time the geometry stage asks about
an epoch of an object (the reception time, the emission times of the light-time
iteration, the velocity's central difference) lies inside that object's window when
``margin_s`` exceeds the light time plus the velocity's half step, so a layer's trajectory
equals each of its objects' own there. The layers are found by interval partitioning
(sorted by start, each object into the layer that ended longest ago; Kleinberg & Tardos,
*Algorithm Design*, 2006, sec. 4.1): as many layers as objects seen at one time at most.
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.orbit.observed_position import position_table, table_position, tt_seconds
from speclight.orbit.orbit_sources import Trajectory

F64 = NDArray[np.float64]


@dataclass(frozen=True)
class ObjectLayer:
    """Objects whose time windows do not overlap, and their joint trajectory.

    Attributes
    ----------
    objects
        Indices of the layer's objects (into the ``object_index`` values).
    rows
        Indices of the rows of those objects, ascending.
    trajectory
        ``t -> (r_gcrs_m (N, 3), ok (N,))``: the position of the object whose window holds
        each time; NaN (``ok`` False) outside every window.
    """

    objects: NDArray[np.intp]
    rows: NDArray[np.intp]
    trajectory: Trajectory


def _partition(start_s: F64, stop_s: F64) -> list[list[int]]:
    """Interval partitioning: groups of intervals ``[start, stop]`` that do not overlap,
    as few as the most intervals holding one time."""
    layers: list[list[int]] = []
    ends: list[tuple[float, int]] = []  # (end of the layer's last interval, layer)
    for i in np.argsort(start_s, kind="stable"):
        if ends and ends[0][0] < start_s[i]:
            _, k = heapq.heappop(ends)
        else:
            k = len(layers)
            layers.append([])
        layers[k].append(int(i))
        heapq.heappush(ends, (float(stop_s[i]), k))
    return layers


def object_layers(
    emitted_utc: NDArray[np.datetime64],
    r_gcrs_m: F64,
    object_index: NDArray[np.intp],
    margin_s: float,
) -> list[ObjectLayer]:
    """Per-object trajectories through observed positions, grouped into layers.

    Parameters
    ----------
    emitted_utc
        (M,) UTC epochs at which the light seen left the target.
    r_gcrs_m
        (M, 3) GCRS positions then [m] (NaN rows: not placed).
    object_index
        (M,) which object each row saw (0 .. K-1).
    margin_s
        Widening of each object's window on both sides [s]: more than the longest light
        time plus the velocity's half step of the geometry stage.

    Returns
    -------
    list of ObjectLayer
        Every object in exactly one layer; the objects without a placed row in none.
    """
    n_objects = int(object_index.max()) + 1 if object_index.size else 0
    placed = np.all(np.isfinite(r_gcrs_m), axis=1)
    tables: dict[int, tuple[F64, F64]] = {}
    ref = 0.0
    for j in range(n_objects):
        rows = np.flatnonzero((object_index == j) & placed)
        if rows.size:
            if not tables:  # one time origin for all: the first placed object's first epoch
                ref = position_table(emitted_utc[rows], r_gcrs_m[rows])[2]
            s_tab, r_tab, _ = position_table(emitted_utc[rows], r_gcrs_m[rows], ref)
            tables[j] = (s_tab, r_tab)
    ids = np.array(sorted(tables), dtype=np.intp)
    start = np.array([tables[j][0][0] - margin_s for j in ids])
    stop = np.array([tables[j][0][-1] + margin_s for j in ids])
    layers = []
    for members in _partition(start, stop):
        order = np.array(members, dtype=np.intp)[np.argsort(start[members])]
        objects = ids[order]
        layers.append(
            ObjectLayer(
                objects=objects,
                rows=np.flatnonzero(np.isin(object_index, objects)),
                trajectory=_layer_trajectory(
                    [tables[j] for j in objects], start[order], stop[order], ref
                ),
            )
        )
    return layers


def _layer_trajectory(
    tables: list[tuple[F64, F64]], start_s: F64, stop_s: F64, ref: float
) -> Trajectory:
    """The trajectory of one layer: windows sorted by start and not overlapping."""

    def trajectory(t: Any) -> tuple[F64, NDArray[np.bool_]]:
        s = tt_seconds(t, ref)
        out = np.full((s.size, 3), np.nan)
        ok = np.zeros(s.size, dtype=bool)
        k = np.searchsorted(start_s, s, side="right") - 1
        inside = (k >= 0) & (s <= stop_s[np.maximum(k, 0)])
        for j in np.unique(k[inside]):
            sel = inside & (k == j)
            out[sel], ok[sel] = table_position(s[sel], *tables[j])
        return out, ok

    return trajectory
