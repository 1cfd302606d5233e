"""The target during an exposure: its direction and brightness between the pipeline's epochs.

The pipeline gives, per epoch, the target's topocentric astrometric right ascension and
declination (ICRS) with their rates, and the count rate per band. Inside an exposure the
direction is the cubic Hermite interpolant of the unit vectors with their time derivatives
``du/dt = (d(RA)/dt cos(Dec) e + d(Dec)/dt n)``, normalised (its error falls as the fourth
power of the step); the count rate is interpolated linearly (a glint shorter than the
pipeline's step is not resolved: make ``time.step_s`` short where it matters).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from speclight.attitude.quaternion import unit_vector_from_radec
from speclight.errors import InputError
from speclight.instrument.imaging.sky_projection import east_north

F64 = NDArray[np.float64]


@dataclass(frozen=True)
class Track:
    """The pipeline's per-epoch quantities the frames need, each with N rows.

    Attributes
    ----------
    time_utc
        Epochs, UTC ``datetime64[ns]``, increasing.
    ra_deg, dec_deg
        Topocentric astrometric ICRS direction of the target [deg].
    ra_cos_dec_rate_deg_s, dec_rate_deg_s
        Its rates [deg s-1] (east, north).
    elevation_deg
        Elevation of the target [deg].
    count_rate
        (N, B) detected photo-electron rate per band [s-1]; NaN where not observable.
    sun_elevation_deg
        Elevation of the Sun at the site [deg], or ``None`` (then computed).
    """

    time_utc: NDArray[np.datetime64]
    ra_deg: F64
    dec_deg: F64
    ra_cos_dec_rate_deg_s: F64
    dec_rate_deg_s: F64
    elevation_deg: F64
    count_rate: F64
    sun_elevation_deg: F64 | None = None

    def seconds(self, t: NDArray[np.datetime64]) -> F64:
        """Seconds of ``t`` after the first epoch."""
        t0 = self.time_utc[0]
        return np.asarray((np.asarray(t, dtype="datetime64[ns]") - t0) / np.timedelta64(1, "s"))


def _bracket(track: Track, t_s: F64) -> tuple[NDArray[np.intp], F64, F64]:
    """Interval index, step [s] and fraction of each time in the track."""
    grid = track.seconds(track.time_utc)
    if grid.size < 2:
        raise InputError(
            "the dataset has one epoch: frames need at least two (time.step_s below the exposure)",
            field="time",
        )
    if np.any(t_s < grid[0] - 1e-9) or np.any(t_s > grid[-1] + 1e-9):
        raise InputError(
            "an exposure reaches outside the dataset's epochs "
            f"(0..{grid[-1]:g} s after {track.time_utc[0]}); start exposures later or "
            "simulate a longer window",
            field="instrument.imaging",
        )
    i = np.clip(np.searchsorted(grid, t_s, side="right") - 1, 0, grid.size - 2)
    h = grid[i + 1] - grid[i]
    return i, h, (t_s - grid[i]) / h


def directions_at(track: Track, t: NDArray[np.datetime64]) -> F64:
    """Unit vectors (P, 3) of the target at times ``t`` (P,) (cubic Hermite, see module)."""
    t_s = track.seconds(t)
    i, h, s = _bracket(track, t_s)
    u = unit_vector_from_radec(track.ra_deg, track.dec_deg)
    east, north = east_north(u)
    rate = np.radians(
        track.ra_cos_dec_rate_deg_s[:, None] * east + track.dec_rate_deg_s[:, None] * north
    )
    s2, s3 = s * s, s * s * s
    h00, h10 = 2 * s3 - 3 * s2 + 1, s3 - 2 * s2 + s
    h01, h11 = -2 * s3 + 3 * s2, s3 - s2
    p = (
        h00[:, None] * u[i]
        + (h10 * h)[:, None] * rate[i]
        + h01[:, None] * u[i + 1]
        + (h11 * h)[:, None] * rate[i + 1]
    )
    return np.asarray(p / np.linalg.norm(p, axis=1, keepdims=True))


def values_at(track: Track, values: F64, t: NDArray[np.datetime64]) -> F64:
    """Linear interpolation of per-epoch ``values`` (N, ...) at times ``t`` (P,)."""
    i, _, s = _bracket(track, track.seconds(t))
    v = np.asarray(values, dtype=np.float64)
    w = s.reshape((-1,) + (1,) * (v.ndim - 1))
    return np.asarray((1.0 - w) * v[i] + w * v[i + 1])
