"""Articulated parts: a part (e.g. a solar array) turned about a hinge axis of the body.

A joint turns one part rigidly about the body-frame line through ``hinge_point_m`` along the
unit ``axis``. Its angle theta is measured right-handed about ``axis`` from the part's pose
as built (theta = 0). ``normal`` is the part's reference normal at theta = 0 (the cell side of
a solar array); the tracking angle depends only on its component perpendicular to the axis.

Laws:

* ``sun_tracking``: the angle that brings the normal closest to the Sun direction s (body
  frame). With n0 the unit normal component perpendicular to the axis and b = axis x n0,
  n(theta) = n0 cos(theta) + b sin(theta) (Rodrigues, n0 perpendicular to the axis), and
  n(theta) . s = (s . n0) cos(theta) + (s . b) sin(theta) is largest at
  theta = atan2(s . b, s . n0). The angle between n and s is then the complement of the
  Sun's elevation above the plane perpendicular to the axis: the single-axis constraint.
* ``table``: theta(t) interpolated linearly in a CSV of ``time_utc,angle_deg`` rows; epochs
  outside the table are an error (no extrapolation).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.input_files import read_user_text
from speclight.target.parts import Part, Target

F64 = NDArray[np.float64]


@dataclass(frozen=True)
class Joint:
    """A hinge turning part ``part`` about ``axis`` through ``hinge_point_m`` (body frame)."""

    part: str
    axis: tuple[float, float, float]
    hinge_point_m: tuple[float, float, float]
    normal: tuple[float, float, float]
    mode: Literal["sun_tracking", "table"]
    table_times_utc: NDArray[np.datetime64] | None = None
    table_angle_deg: F64 | None = None

    def __post_init__(self) -> None:
        where = f"target.articulation.{self.part}"
        a = np.asarray(self.axis, float)
        if a.shape != (3,) or not np.all(np.isfinite(a)) or np.linalg.norm(a) == 0:
            raise InputError(f"axis {list(self.axis)} must be a non-zero 3-vector", field=where)
        n = np.asarray(self.normal, float)
        a = a / np.linalg.norm(a)
        perp = n - a * (n @ a)
        size = float(np.linalg.norm(n))
        if n.shape != (3,) or not float(np.linalg.norm(perp)) > 1e-6 * max(size, 1e-300):
            raise InputError(
                f"normal {list(self.normal)} must be a 3-vector not parallel to the axis "
                f"{list(self.axis)} (a normal along the hinge does not turn)",
                field=where,
            )
        if self.mode == "table" and (self.table_times_utc is None or self.table_angle_deg is None):
            raise InputError("mode 'table' needs table_file", field=where)

    @property
    def unit_axis(self) -> F64:
        """The unit hinge axis (body frame)."""
        a = np.asarray(self.axis, float)
        return a / np.linalg.norm(a)

    @property
    def n0(self) -> F64:
        """The unit reference normal perpendicular to the axis, at theta = 0."""
        a, n = self.unit_axis, np.asarray(self.normal, float)
        perp = n - a * (n @ a)
        return perp / np.linalg.norm(perp)

    def angles_rad(self, sun_body: F64, time_utc: NDArray[np.datetime64]) -> F64:
        """(N,) hinge angles [rad] for Sun directions (N, 3) (body frame) at ``time_utc``."""
        if self.mode == "sun_tracking":
            return sun_tracking_angle_rad(self.unit_axis, self.n0, sun_body)
        assert self.table_times_utc is not None and self.table_angle_deg is not None
        knots = self.table_times_utc.astype("datetime64[ns]").astype(np.int64)
        at = np.asarray(time_utc, dtype="datetime64[ns]").astype(np.int64)
        out = (at < knots[0]) | (at > knots[-1])
        if np.any(out):
            first = np.asarray(time_utc)[np.flatnonzero(out)[0]]
            raise InputError(
                f"epoch {first} is outside the angle table ({self.table_times_utc[0]} .. "
                f"{self.table_times_utc[-1]}); the table is not extrapolated",
                field=f"target.articulation.{self.part}.table_file",
            )
        return np.radians(np.interp(at - knots[0], knots - knots[0], self.table_angle_deg))


def joint_angles_rad(
    joints: tuple[Joint, ...], sun_body: F64, time_utc: NDArray[np.datetime64]
) -> F64:
    """(N, J) every joint's angle [rad] at each epoch (Sun directions (N, 3), body frame)."""
    return np.stack([j.angles_rad(sun_body, time_utc) for j in joints], axis=1)


def sun_tracking_angle_rad(axis: F64, n0: F64, sun_body: F64) -> F64:
    """Hinge angle [rad] bringing the normal closest to the Sun (see the module doc)."""
    b = np.cross(axis, n0)
    return np.arctan2(np.asarray(sun_body) @ b, np.asarray(sun_body) @ n0)


def rotation_matrix(axis: F64, angle_rad: float) -> F64:
    """Right-handed rotation by ``angle_rad`` about the unit ``axis`` (Rodrigues' formula)."""
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle_rad) * k + (1.0 - np.cos(angle_rad)) * (k @ k)


def posed_target(target: Target, joints: tuple[Joint, ...], angles_rad: F64) -> Target:
    """``target`` with each joint's part turned by its angle (``angles_rad`` (J,))."""
    turned = {j.part: (j, float(t)) for j, t in zip(joints, angles_rad, strict=True)}
    parts: list[Part] = []
    for p in target.parts:
        if p.name not in turned:
            parts.append(p)
            continue
        j, t = turned[p.name]
        r = rotation_matrix(j.unit_axis, t)
        hinge = np.asarray(j.hinge_point_m, float)
        v = (p.vertices_m - hinge) @ r.T + hinge
        centre = tuple((r @ (np.asarray(p.sphere_center_m) - hinge) + hinge).tolist())
        parts.append(replace(p, vertices_m=v, sphere_center_m=centre))
    return Target(tuple(parts))


def check_joint_parts(target: Target, joints: tuple[Joint, ...]) -> None:
    """Refuse a joint naming a part the target does not have."""
    names = target.part_names
    for j in joints:
        if j.part not in names:
            from speclight.errors import did_you_mean

            raise InputError(
                f"articulated part '{j.part}' is not a part of the shape"
                f"{did_you_mean(j.part, names)} (parts: {', '.join(names)})",
                field=f"target.articulation.{j.part}",
            )


def _angle_row(line: str) -> tuple[np.datetime64, float]:
    """The time and angle of a row ``time_utc,angle_deg``; ValueError if it is not one."""
    cells = [c.strip() for c in line.split(",")]
    if len(cells) != 2:
        raise ValueError("not 2 cells")
    t = np.datetime64(cells[0][:-1] if cells[0].upper().endswith("Z") else cells[0])
    a = float(cells[1])
    if not np.isfinite(a) or np.isnat(t):
        raise ValueError("not finite")
    return t, a


def read_angle_table(path: str | Path, field: str) -> tuple[NDArray[np.datetime64], F64]:
    """Read a CSV ``time_utc,angle_deg`` (header row, ISO UTC times, strictly increasing)."""
    text = read_user_text(Path(path), field)
    times: list[np.datetime64] = []
    angles: list[float] = []
    for lineno, line in enumerate(text.splitlines(), start=1):
        s = line.split("#", 1)[0].strip()
        if not s or s.replace(" ", "").lower() == "time_utc,angle_deg":
            continue
        try:
            t, a = _angle_row(s)
        except ValueError:
            raise InputError(
                f"line {lineno} {s[:60]!r}: expected 'time_utc,angle_deg' (ISO UTC time, degrees)",
                source=str(path),
                field=field,
            ) from None
        times.append(t.astype("datetime64[ns]"))
        angles.append(a)
    t_arr = np.array(times, dtype="datetime64[ns]")
    if len(t_arr) < 2 or np.any(np.diff(t_arr) <= np.timedelta64(0, "ns")):
        raise InputError(
            f"{len(t_arr)} rows; need at least 2 with strictly increasing times",
            source=str(path),
            field=field,
        )
    return t_arr, np.asarray(angles, float)
