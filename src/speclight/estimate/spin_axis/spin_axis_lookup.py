"""Band count rates of a reflectivity map, looked up for many spin axes and phases at once.

A spin about the body axis ``b`` turns the body frame about ``b``; in the **spin frame**
(the body frame turned by ``m``, the smallest rotation taking ``b`` to z:
:func:`speclight.attitude.spin.body_axis_to_z`) a change of the rotation phase is a shift
of the azimuth about z and nothing else. So the map is resampled once onto a regular grid
of the spin frame (polar angle x azimuth x the map's phase angles x rolls, the roll measured
from the spin frame's own east/north axes, which a turn about z leaves unchanged) with the
map's own interpolation (:meth:`speclight.maps.map_lookup.ReflectivityMap.intensity_1au`,
HEALPix bilinear, linear in phase angle and roll). The azimuth step divides the phase step
``360 / n_phases`` by an integer ``m``, so the ``n_phases`` candidate phases of one
(axis, epoch) read one contiguous run of the grid: a window of a sliding-window view, no
Python loop per candidate. The polar angle and azimuth are looked up at the nearest grid
cell (the grid is a few times finer than the map), the phase angle and roll linearly
(:mod:`.spin_axis_grid` does the lookups and the misfit sums for a whole grid of axes).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.attitude.quaternion import quat_to_matrix
from speclight.attitude.spin import body_axis_to_z
from speclight.errors import InputError
from speclight.maps.map_geometry import sun_observer
from speclight.maps.map_lookup import ReflectivityMap, read_header

F64 = NDArray[np.float64]
F32 = NDArray[np.float32]
FIELD = "map_path"


def load_band_map(path: str | Path) -> ReflectivityMap:
    """A complete map with its band count rates ``count_rate (D, P, R, B)`` [s-1] in place of
    the intensity, so that :meth:`ReflectivityMap.intensity_1au` interpolates band rates."""
    import zarr

    header = read_header(path)
    group: Any = zarr.open_group(str(path), mode="r")
    if "count_rate" not in group or not header.band_names:
        raise InputError(
            f"the map {path} has no band count rates (it was made from a scenario without "
            "instrument.bands); make it again with the scenario's bands",
            field=FIELD,
        )
    return ReflectivityMap(
        header=header,
        direction_body=np.asarray(group["direction_body"][...], dtype=float),
        intensity_W_sr_nm=np.asarray(group["count_rate"][...], dtype=np.float32),
    )


@dataclass(frozen=True)
class SpinFrameMap:
    """Band rates on the spin-frame grid, each band divided by its mean over the grid.

    ``values`` has shape (n_polar, m, P, R, 2 n_phases, B): polar cell ``i`` (centre
    ``(i + 0.5) * 180 / n_polar`` deg), azimuth cell ``c = q m + s`` (centre ``c * 360 /
    (n_phases m)`` deg) stored at ``[i, s, ..., 2 n_phases - 1 - q]`` and again at
    ``n_phases - 1 - q`` (so that the cells ``q, q - 1, ...`` of the phases ``0, 1, ...`` are
    one contiguous window), the map's phase angles ``P`` and rolls ``R``.
    """

    values: F32
    n_phases: int
    m: int
    phase_angle_deg: F64
    n_rolls: int
    spin_to_body: F64  # (3, 3): body vector = spin_to_body @ spin-frame vector
    scale: F64 | None = None  # (B,) what each band was divided by (None: ones)

    @property
    def n_polar(self) -> int:
        return int(self.values.shape[0])


def cell_deg_for(nside: int) -> float:
    """Grid cell of the spin frame [deg]: a third of the map's pixel spacing, 0.5..3 deg."""
    spacing = np.degrees(np.sqrt(4 * np.pi / (12 * nside**2)))
    return float(np.clip(spacing / 3, 0.5, 3.0))


def spin_frame_map(
    bmap: ReflectivityMap,
    spin_body_axis: ArrayLike | None,
    n_phases: int,
    cell_deg: float | None = None,
) -> SpinFrameMap:
    """Resample a band map onto the spin frame of ``spin_body_axis`` (module docstring)."""
    cell = cell_deg_for(bmap.header.nside) if cell_deg is None else float(cell_deg)
    step = 360.0 / n_phases
    m = max(1, int(np.ceil(step / cell)))
    n_az = n_phases * m
    n_polar = max(2, int(np.ceil(180.0 / cell)))
    q_m = body_axis_to_z(spin_body_axis)
    spin_to_body = np.eye(3) if q_m is None else quat_to_matrix(q_m).T
    polar = np.radians((np.arange(n_polar) + 0.5) * 180.0 / n_polar)
    az = np.radians(np.arange(n_az) * 360.0 / n_az)
    pp, aa = np.meshgrid(polar, az, indexing="ij")
    p = np.stack([np.sin(pp) * np.cos(aa), np.sin(pp) * np.sin(aa), np.cos(pp)], -1).reshape(-1, 3)
    angles = bmap.header.phase_angle_deg
    n_rolls = bmap.header.roll_deg.size
    rolls = 2 * np.pi * np.arange(n_rolls) / n_rolls
    n_b = bmap.intensity_W_sr_nm.shape[-1]
    out = np.empty((n_polar, n_az, angles.size, n_rolls, n_b), dtype=np.float32)
    for j, a in enumerate(np.radians(angles)):
        for k, r in enumerate(rolls):
            s, o = sun_observer(p, a, r)
            rate = bmap.intensity_1au(s @ spin_to_body.T, o @ spin_to_body.T)
            out[:, :, j, k] = rate.reshape(n_polar, n_az, n_b)
    # Each band divided by its mean over the grid: the search divides every light curve by
    # its mean anyway, and rates of ~1e20 s-1 (1 m, 1 m2) would overflow float32 squares.
    with np.errstate(invalid="ignore", divide="ignore"):
        scale = np.nanmean(out.reshape(-1, n_b).astype(float), axis=0)
        scale = np.where(scale > 0, scale, 1.0)
        out /= scale.astype(np.float32)
    # (polar, q, s, P, R, B) -> (polar, s, P, R, q, B), doubled along q
    grid = out.reshape(n_polar, n_phases, m, angles.size, n_rolls, n_b).transpose(0, 2, 3, 4, 1, 5)
    # stored reversed along q, so that the window of phases 0, 1, ... reads forwards
    values = np.ascontiguousarray(np.concatenate([grid, grid], axis=4)[:, :, :, :, ::-1])
    return SpinFrameMap(values, n_phases, m, angles, n_rolls, spin_to_body, scale)


def axis_frames(ra_deg: ArrayLike, dec_deg: ArrayLike) -> F64:
    """Body-to-GCRS matrices (A, 3, 3) of the spin reference frames at phase 0 (columns x, y,
    z; z on the axis, x on the ascending node; :func:`speclight.attitude.spin_reference_frame`)."""
    ra = np.radians(np.asarray(ra_deg, dtype=float).ravel())
    dec = np.radians(np.asarray(dec_deg, dtype=float).ravel())
    z = np.stack([np.cos(dec) * np.cos(ra), np.cos(dec) * np.sin(ra), np.sin(dec)], -1)
    x = np.cross([0.0, 0.0, 1.0], z)
    norm = np.linalg.norm(x, axis=1)
    polar = norm < 1e-9
    x[polar] = [1.0, 0.0, 0.0]
    x -= np.sum(x * z, axis=1)[:, None] * z
    x /= np.linalg.norm(x, axis=1)[:, None]
    return np.stack([x, np.cross(z, x), z], axis=-1)


@dataclass(frozen=True)
class EpochGeometry:
    """Inertial directions of the measured epochs (unit vectors from the target, GCRS)."""

    sun_gcrs: F64  # (T, 3)
    observer_gcrs: F64  # (T, 3)
    t_s: F64  # (T,) seconds since the scenario start
    period_s: float


def angular_distance_deg(ra1: ArrayLike, dec1: ArrayLike, ra2: ArrayLike, dec2: ArrayLike) -> F64:
    """Great-circle distance [deg] between RA/Dec pairs [deg]."""
    r1, d1, r2, d2 = (np.radians(np.asarray(v, dtype=float)) for v in (ra1, dec1, ra2, dec2))
    c = np.sin(d1) * np.sin(d2) + np.cos(d1) * np.cos(d2) * np.cos(r1 - r2)
    return np.degrees(np.arccos(np.clip(c, -1.0, 1.0)))
